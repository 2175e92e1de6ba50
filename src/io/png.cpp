#include "pdcg/io/png.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "pdcg/core/error.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace pdcg::io {

namespace {

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 24));
  out.push_back(static_cast<std::uint8_t>(v >> 16));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}

void chunk(std::vector<std::uint8_t>& out, const char type[4], const std::vector<std::uint8_t>& data) {
  put_u32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  const uLong crc = crc32(0L, out.data() + start, static_cast<uInt>(out.size() - start));
  put_u32(out, static_cast<std::uint32_t>(crc));
}

}  // namespace

void write_png(const std::filesystem::path& path, int width, int height, std::span<const std::uint8_t> rgb) {
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<std::size_t>(width) * height * 3)
    throw Error("write_png: image size does not match the pixel buffer");
  // Raw scanlines, each prefixed by filter type 0.
  std::vector<std::uint8_t> raw;
  raw.reserve(static_cast<std::size_t>(height) * (3 * width + 1));
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    const auto* row = rgb.data() + static_cast<std::size_t>(y) * width * 3;
    raw.insert(raw.end(), row, row + static_cast<std::size_t>(width) * 3);
  }
  uLongf zlen = compressBound(static_cast<uLong>(raw.size()));
  std::vector<std::uint8_t> z(zlen);
  if (compress2(z.data(), &zlen, raw.data(), static_cast<uLong>(raw.size()), 6) != Z_OK)
    throw Error("write_png: zlib compression failed");
  z.resize(zlen);

  std::vector<std::uint8_t> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<std::uint8_t> ihdr;
  put_u32(ihdr, static_cast<std::uint32_t>(width));
  put_u32(ihdr, static_cast<std::uint32_t>(height));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8-bit, truecolour, deflate, no filter, no interlace
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", {});

  AtomicTextFile out(path);
  out.stream().write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  out.commit();
}

void write_png_field(const std::filesystem::path& path, int width, int height, std::span<const double> v,
                     bool log_scale) {
  if (v.size() != static_cast<std::size_t>(width) * height)
    throw Error("write_png_field: value count does not match the image size");
  double vmax = 0.0, vmin = INFINITY;
  for (double x : v)
    if (std::isfinite(x)) {
      vmax = std::max(vmax, x);
      vmin = std::min(vmin, x);
    }
  // Viridis control points (matplotlib's colormap at 0, .25, .5, .75, 1).
  static constexpr std::array<std::array<double, 3>, 5> cmap{{{68, 1, 84}, {59, 82, 139}, {33, 145, 140},
                                                             {94, 201, 98}, {253, 231, 37}}};
  std::vector<std::uint8_t> rgb(v.size() * 3);
  for (std::size_t i = 0; i < v.size(); ++i) {
    double s;
    if (!std::isfinite(v[i])) {
      s = 0.0;
    } else if (log_scale) {
      const double lo = vmax * 1e-6;
      s = vmax > 0 ? (std::log10(std::max(v[i], lo)) - std::log10(lo)) / 6.0 : 0.0;
    } else {
      s = vmax > vmin ? (v[i] - vmin) / (vmax - vmin) : 0.0;
    }
    s = std::clamp(s, 0.0, 1.0) * 4.0;
    const auto k = std::min<std::size_t>(3, static_cast<std::size_t>(s));
    const double f = s - static_cast<double>(k);
    for (int c = 0; c < 3; ++c)
      rgb[3 * i + static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(
          std::lround((1 - f) * cmap[k][static_cast<std::size_t>(c)] + f * cmap[k + 1][static_cast<std::size_t>(c)]));
  }
  write_png(path, width, height, rgb);
}

}  // namespace pdcg::io
