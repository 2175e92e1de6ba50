#!/usr/bin/env bash
# CLI behaviour of the pdcg executable: help, version, exit codes.
# Usage: cli_basics.sh /path/to/pdcg
set -u
pdcg=$1
fail=0
check() {  # check <name> <expected-exit> <regex-on-output> <args...>
  local name=$1 want=$2 regex=$3; shift 3
  local out code
  out=$("$pdcg" "$@" 2>&1); code=$?
  if [ "$code" != "$want" ]; then
    echo "FAIL $name: exit $code, expected $want"; echo "$out" | head -20; fail=1; return
  fi
  if ! grep -Eq -- "$regex" <<<"$out"; then
    echo "FAIL $name: output does not match /$regex/"; echo "$out" | head -20; fail=1; return
  fi
  echo "ok   $name"
}
check help          0 'Subcommands:'                 --help
check help-lists    0 'version +Print the versions'  --help
check version       0 'Eigen +3\.'                   version
check version-libs  0 'HDF5 +1\.'                    version
check version-fftw  0 'FFTW +fftw-3'                 version
check version-ss    0 'SuiteSparse +[0-9]'           version
check version-petsc 0 'PETSc +([0-9]+\.[0-9]+|not enabled)' version
check version-mpi   0 'MPI +[A-Za-z]|PETSc +not enabled' version
check version-help  0 'Example:'                     version --help
check info-help     0 'pdcg info body.h5'            info --help
check unknown       2 "unknown command 'frobnicate'.*Valid commands:" frobnicate
check no-command    2 'subcommand is required|A subcommand is required' 
check bad-option    2 "pdcg: .*--no-such-option"     version --no-such-option
check info-missing  2 'file not found.*nope.h5'      info nope.h5
check verbose-quiet 2 'contradict'                   -v -q version
# stdout carries results, stderr messages: an error prints nothing on stdout
out=$("$pdcg" frobnicate 2>/dev/null)
if [ -n "$out" ]; then echo "FAIL stderr-only: error text on stdout"; fail=1; else echo "ok   stderr-only"; fi
if [ $fail -ne 0 ]; then echo "cli_basics: FAILED"; exit 1; fi
echo "cli_basics: all passed"
