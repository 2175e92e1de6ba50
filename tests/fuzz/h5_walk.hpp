/// \file
/// What `pdcg info` and a restart do with a result, checkpoint or body file, through the
/// generic H5Reader: the root's identification, then every group, dataset and the attributes
/// the readers ask for, two levels deep, each dataset read as every type (a mismatched type
/// must be refused with an InputError, never misread). Shared by h5_result and h5_struct.
#pragma once

#include <functional>
#include <string>

#include "pdcg/core/error.hpp"
#include "pdcg/io/hdf5.hpp"

namespace pdcg::fuzz {

inline void walk_h5(const pdcg::io::H5Reader& file) {
  (void)file.info();
  for (const char* a : {"kind", "step", "t", "dimension", "points"})
    if (file.has_attribute("/", a)) {
      try {
        (void)file.attribute_string("/", a);
      } catch (const pdcg::Error&) {
        (void)file.attribute_double("/", a);
      }
    }
  std::function<void(const std::string&, int)> walk = [&](const std::string& group, int depth) {
    for (const auto& name : file.list(group)) {
      const std::string p = (group == "/" ? "" : group) + "/" + name;
      bool is_group = true;
      try {
        (void)file.list(p);
      } catch (const pdcg::Error&) {
        is_group = false;
      }
      if (is_group) {
        if (depth < 2) walk(p, depth + 1);
        continue;
      }
      (void)file.dims(p);
      for (int kind = 0; kind < 4; ++kind) try {
          if (kind == 0) (void)file.read_double(p);
          if (kind == 1) (void)file.read_int(p);
          if (kind == 2) (void)file.read_string(p);
          if (kind == 3) (void)file.read_strings(p);
        } catch (const pdcg::Error&) {
        }
    }
  };
  walk("/", 0);
}

}  // namespace pdcg::fuzz
