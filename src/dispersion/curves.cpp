#include "pdcg/dispersion/curves.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "pdcg/core/error.hpp"
#include "pdcg/core/parse.hpp"

namespace pdcg::dispersion {

Curves read_curves(const std::string& path, const std::string& option) {
  std::ifstream in(path);
  if (!in)
    throw InputError("cannot open curve file").key(option).value(path).expected("a readable CSV file");
  std::string line;
  long lineno = 1;
  // leading `#` lines (pdcg's units line, docs/formats.md) are comments
  bool got = false;
  while ((got = static_cast<bool>(std::getline(in, line))) && line.rfind('#', 0) == 0) ++lineno;
  if (!got) throw InputError("empty curve file").source(path).key(option);
  std::vector<std::string> header;
  std::stringstream hs(line);
  for (std::string h; std::getline(hs, h, ',');) header.emplace_back(trim(h));
  int kcol = -1;
  std::vector<std::size_t> wcols;
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (header[c] == "kappa") kcol = static_cast<int>(c);
    if (header[c].rfind("omega", 0) == 0 && header[c].rfind("omega_ref", 0) != 0) wcols.push_back(c);
  }
  if (kcol < 0 || wcols.empty())
    throw InputError("curve file lacks the columns it needs")
        .source(path)
        .line(lineno)
        .value(line)
        .expected("a header with `kappa` and at least one `omega…` column")
        .fix("use a CSV written by `pdcg dispersion`, or write one with those headers");
  Curves c;
  for (auto w : wcols) c.names.push_back(header[w]);
  c.omega.resize(wcols.size());
  while (std::getline(in, line)) {
    ++lineno;
    if (trim(line).empty()) continue;
    std::vector<std::string> f;
    std::stringstream ls(line);
    for (std::string v; std::getline(ls, v, ',');) f.push_back(v);
    if (f.size() < header.size())
      throw InputError("fewer columns than the header")
          .source(path)
          .line(lineno)
          .value(line)
          .expected(std::to_string(header.size()) + " comma-separated values");
    c.kappa.push_back(parse_double(trim(f[static_cast<std::size_t>(kcol)]), {path, lineno, "kappa"}));
    for (std::size_t b = 0; b < wcols.size(); ++b)
      c.omega[b].push_back(parse_double(trim(f[wcols[b]]), {path, lineno, header[wcols[b]]}));
  }
  if (c.kappa.empty()) throw InputError("curve file has no data rows").source(path).key(option);
  return c;
}

double interpolate(const Curves& c, std::size_t b, double k) {
  for (std::size_t i = 0; i + 1 < c.kappa.size(); ++i) {
    const double k0 = c.kappa[i], k1 = c.kappa[i + 1];
    if ((k >= k0 && k <= k1) || (k <= k0 && k >= k1)) {
      const double s = k1 == k0 ? 0.0 : (k - k0) / (k1 - k0);
      return c.omega[b][i] + s * (c.omega[b][i + 1] - c.omega[b][i]);
    }
  }
  if (std::abs(k - c.kappa.back()) <= 1e-12 * std::max(1.0, std::abs(k))) return c.omega[b].back();
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace pdcg::dispersion
