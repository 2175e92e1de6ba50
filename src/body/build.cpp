#include "pdcg/body/build.hpp"

#include <fmt/format.h>

#include <string>
#include <vector>

#include "pdcg/body/model_file.hpp"
#include "pdcg/body/statistics.hpp"
#include "pdcg/core/error.hpp"

namespace pdcg::body {

namespace {

/// The option `name` (snake_case) as the user types it: "--family-cutoff" / "family_cutoff".
std::string option(OptionSpelling s, std::string name) {
  if (s == OptionSpelling::python) return name;
  for (auto& c : name)
    if (c == '_') c = '-';
  return "--" + name;
}

/// The option with a value placeholder: "--width W" / "width=W".
std::string usage(OptionSpelling s, const std::string& name, const std::string& value) {
  return s == OptionSpelling::python ? name + "=" + value : option(s, name) + " " + value;
}

}  // namespace

Body build_body(std::span<const atomistic::Atoms> frames,
                std::shared_ptr<const atomistic::Potential> pot,
                const atomistic::PotentialSpec& spec, const BodyRequest& r) {
  const OptionSpelling sp = r.spelling;
  const bool cli = sp == OptionSpelling::command_line;
  if (frames.empty()) throw InputError("no configuration given").key(cli ? "--input" : "atoms");
  const bool statistical = !r.statistics.empty();
  if (statistical && r.statistics != "gaussian" && r.statistics != "empirical")
    throw InputError("unknown statistics")
        .key(option(sp, "statistics"))
        .value(r.statistics)
        .expected("gaussian or empirical");
  if (statistical && r.order && r.samples)
    throw InputError(cli ? "give one of --order and --samples" : "give one of order= and samples=")
        .key(cli ? "--order/--samples" : "order/samples");
  DeltaBodyOptions opt = r.delta;
  if (r.family_cutoff) {
    if (!(*r.family_cutoff >= pot->cutoff())) {
      InputError e("family cutoff below the potential's cutoff");
      if (cli)
        e.source(option(sp, "family_cutoff"));
      else
        e.key(option(sp, "family_cutoff"));
      e.value(fmt::format("{}", *r.family_cutoff))
          .expected(fmt::format("at least the potential cutoff {}", pot->cutoff()));
      if (cli) e.fix("omit --family-cutoff, or give the cutoff plus a skin");
      throw e;
    }
    opt.cutoff = *r.family_cutoff;
  }
  const atomistic::Atoms& ref = frames.front();
  Body b = make_delta_body(ref, pot, spec, opt);
  b.potential_files = embed_potential_files(b.potential_spec);
  b.provenance.back() += r.provenance;
  if (!statistical) return b;

  if (r.width && r.temperature)
    throw InputError(
        fmt::format("give one of {} and {}", option(sp, "width"), option(sp, "temperature")))
        .key(option(sp, "temperature"));
  Statistics s;
  if (r.statistics == "empirical") {
    if (r.width || r.temperature)
      throw InputError(fmt::format("{} and {} belong to gaussian statistics", option(sp, "width"),
                                   option(sp, "temperature")))
          .key(option(sp, "statistics"))
          .value("empirical")
          .fix("drop them, or use gaussian statistics");
    s = empirical_from_frames(b, frames);
  } else if (r.temperature) {
    if (frames.size() > 1)
      throw InputError(cli ? "give --temperature or several frames, not both"
                           : "give temperature= or several frames, not both")
          .key(option(sp, "temperature"))
          .fix(
              "the frames give the widths themselves (mean and covariance per atom); "
              "--temperature estimates them from one (relaxed) configuration");
    s = einstein_statistics(b, *r.temperature, option(sp, "temperature"));
  } else if (r.width) {
    if (frames.size() > 1)
      throw InputError(cli ? "give --width or several frames, not both"
                           : "give width= or several frames, not both")
          .key(option(sp, "width"));
    s = isotropic_gaussian(b, *r.width);
  } else {
    if (frames.size() < 2)
      throw InputError("gaussian densities need a width or several frames")
          .key(cli ? "--statistics gaussian" : "statistics='gaussian'")
          .fix(cli ? "give --frames A:B (mean and covariance per atom), --width W (isotropic) "
                     "or --temperature T (local-harmonic widths)"
                   : "give frames (mean and covariance per atom), width=W (isotropic) or "
                     "temperature=T (local-harmonic widths)");
    s = gaussian_from_frames(b, frames);
  }
  if (r.samples) {
    s.method = Statistics::Method::sampling;
    s.samples = *r.samples;
  } else {
    s.method = pot->pairwise() ? Statistics::Method::cubature : Statistics::Method::sampling;
    if (r.order && !pot->pairwise())
      throw InputError("Gauss–Hermite cubature needs a pair potential")
          .key(option(sp, "order"))
          .value(pot->style())
          .fix(fmt::format("use {} for many-body potentials", usage(sp, "samples", "N")));
    if (r.order) s.order = *r.order;
  }
  if (frames.size() > 1) {
    // families of the mean configuration (not of the first frame): rebuild the delta body at
    // the means the statistics moved the points to
    atomistic::Atoms mean = ref;
    atomistic::sort_by_id(mean, r.delta.source);
    mean.x = b.x;
    auto files = std::move(b.potential_files);
    auto prov = std::move(b.provenance);
    b = make_delta_body(mean, pot, spec, opt);
    b.potential_files = std::move(files);
    b.provenance = std::move(prov);
    b.provenance.push_back(
        fmt::format("families rebuilt at the mean positions of {} frames", frames.size()));
  }
  make_statistical(b, std::move(s));
  return b;
}

}  // namespace pdcg::body
