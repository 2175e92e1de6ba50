# Sanitizer and fuzzing builds (docs/testing.md "Sanitizers and fuzzing").
#
#   -DPDCG_SANITIZE=address,undefined   every target compiled and linked with
#                                       -fsanitize=<list> (GCC or clang), errors fatal
#   -DPDCG_FUZZ=ON                      (clang only) the libFuzzer harnesses of tests/fuzz;
#                                       implies PDCG_SANITIZE=address,undefined when unset
# Both want -O1 -g -fno-omit-frame-pointer (tests/sanitize.sh and tests/fuzz/run.sh pass
# CMAKE_BUILD_TYPE=RelWithDebInfo with those flags).
set(PDCG_SANITIZE "" CACHE STRING "Sanitizers for every target, e.g. address,undefined (empty: none)")
option(PDCG_FUZZ "Build the libFuzzer harnesses of tests/fuzz (clang)" OFF)
option(PDCG_SANITIZE_TEST_CODE_O0 "With sanitizers: compile the tests' own code at -O0 (libraries keep their flags); off: measured slower overall" OFF)

if(PDCG_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "PDCG_FUZZ=ON needs clang (libFuzzer), e.g. -DCMAKE_CXX_COMPILER=clang++-14 "
                        "-DCMAKE_C_COMPILER=clang-14; CMAKE_CXX_COMPILER_ID is ${CMAKE_CXX_COMPILER_ID}")
  endif()
  if(NOT PDCG_SANITIZE)
    set(PDCG_SANITIZE "address,undefined" CACHE STRING "" FORCE)
  endif()
  # coverage instrumentation of the libraries; the harness executables add -fsanitize=fuzzer
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()

if(PDCG_SANITIZE)
  # -fno-sanitize-recover: a UBSan report fails the test instead of printing and going on
  add_compile_options(-fsanitize=${PDCG_SANITIZE} -fno-sanitize-recover=all
                      -fno-omit-frame-pointer)
  add_link_options(-fsanitize=${PDCG_SANITIZE} -fno-sanitize-recover=all)
endif()
