/// \file
/// Minimal PNG writer (8-bit RGB, zlib) for images the CLI draws itself, e.g. the power
/// spectrum S(κ, ω). Written atomically. Plots with axes and legends come from the workflow
/// scripts (matplotlib); this is for raw fields.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

namespace pdcg::io {

/// rgb: width·height·3 bytes, rows top to bottom.
void write_png(const std::filesystem::path& path, int width, int height, std::span<const std::uint8_t> rgb);

/// Maps values (row-major, rows top to bottom) to a perceptual colour map (viridis
/// approximation); log_scale maps log10(value) over the range [max·1e-6, max].
void write_png_field(const std::filesystem::path& path, int width, int height, std::span<const double> values,
                     bool log_scale);

}  // namespace pdcg::io
