// sm_harness: slivermesh (through its C ABI, linked from the installed package) against CGAL
// Mesh_3 on the same input at the same tet count, both meshes measured by the same code
// (ctests/tet_quality.hpp), written through VTK and read back, and a side-by-side table.
//
//   sm_harness INPUT.off|INPUT.poly [--tets N] [--size H] [--cgal-size S] [--outdir DIR]
//              [--tol F] [--count-tol F] [--max-runs N] [--repeat N] [--no-merge] [--no-cgal]
//              [--param NAME=VALUE]... [--check-larger-min-dihedral]
//              [--require-min-dihedral DEG] [--volume-tol F] [--volume V]
//              [--expect-regions LIST] [--expect-markers LIST]
//
// Sizes: slivermesh's constant spacing h is adjusted until about --tets tets (default 8000),
// then CGAL's size s until its count is within --tol (5%) of ours (--size / --cgal-size fix
// them). Files in --outdir (default .): MODEL-slivermesh.vtu, MODEL-slivermesh-boundary.vtu,
// MODEL-cgal.vtu, MODEL-cgal-boundary.vtu.
//
// Checks, each failure printed as "FAIL: ..." (exit status 1; 2 for usage errors): slivermesh
// completes; no inverted tet (orientation of the measured volume) in either mesh; our volume
// within --volume-tol (0.5%) of the input's (.off inputs, or --volume V); the tet counts within --count-tol
// (20%); with --expect-regions / --expect-markers the sets of our tets' regions and boundary
// markers equal the comma-separated lists; the .vtu files read back by VTK with the right point and cell counts, cell types, cell
// data and re-measured minimum dihedral angle; with --check-larger-min-dihedral our minimum
// dihedral angle larger than CGAL's; with --require-min-dihedral ours at least DEG. Times are
// printed, never asserted.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include "domain.hpp"
#include "mesh.hpp"
#include "meshers.hpp"

namespace {

using namespace harness;

struct Options {
  std::string input, outdir = ".";
  std::size_t tets = 8000;
  double size = 0.0, cgal_size = 0.0;
  double tol = 0.05, count_tol = 0.20, volume_tol = 0.005;
  int max_runs = 6, repeat = 1;
  bool merge = true, cgal = true, larger_min_dihedral = false;
  std::optional<double> require_min_dihedral, volume;
  std::optional<std::set<int32_t>> expect_regions, expect_markers;
  std::vector<std::pair<std::string, double>> params;
};

[[noreturn]] void usage(const std::string& why) {
  std::cerr << "error: " << why << "\n"
            << "usage: sm_harness INPUT.off|INPUT.poly [--tets N] [--size H] [--cgal-size S]\n"
            << "         [--outdir DIR] [--tol F] [--count-tol F] [--max-runs N] [--repeat N]\n"
            << "         [--no-merge] [--no-cgal] [--param NAME=VALUE]...\n"
            << "         [--check-larger-min-dihedral] [--require-min-dihedral DEG]\n"
            << "         [--volume-tol F] [--volume V] [--expect-regions LIST]\n"
            << "         [--expect-markers LIST]\n";
  std::exit(2);
}

std::set<int32_t> int_list(const std::string& flag, const std::string& text) {
  std::set<int32_t> out;
  std::istringstream in(text);
  for (std::string w; std::getline(in, w, ',');) {
    char* end = nullptr;
    const long v = std::strtol(w.c_str(), &end, 10);
    if (w.empty() || *end != '\0') usage(flag + " needs a comma-separated list of integers");
    out.insert(static_cast<int32_t>(v));
  }
  return out;
}

double number(const std::string& flag, const std::string& text, double lo) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || v < lo)
    usage(flag + " needs a finite number >= " + std::to_string(lo) + ", got '" + text + "'");
  return v;
}

Options parse_args(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(a + " needs a value");
      return argv[++i];
    };
    if (a == "--tets") o.tets = static_cast<std::size_t>(number(a, value(), 50));
    else if (a == "--size") o.size = number(a, value(), 1e-300);
    else if (a == "--cgal-size") o.cgal_size = number(a, value(), 1e-300);
    else if (a == "--outdir") o.outdir = value();
    else if (a == "--tol") o.tol = number(a, value(), 0);
    else if (a == "--count-tol") o.count_tol = number(a, value(), 0);
    else if (a == "--volume-tol") o.volume_tol = number(a, value(), 0);
    else if (a == "--max-runs") o.max_runs = static_cast<int>(number(a, value(), 1));
    else if (a == "--repeat") o.repeat = static_cast<int>(number(a, value(), 1));
    else if (a == "--no-merge") o.merge = false;
    else if (a == "--no-cgal") o.cgal = false;
    else if (a == "--check-larger-min-dihedral") o.larger_min_dihedral = true;
    else if (a == "--require-min-dihedral") o.require_min_dihedral = number(a, value(), 0);
    else if (a == "--volume") o.volume = number(a, value(), 1e-300);
    else if (a == "--expect-regions") o.expect_regions = int_list(a, value());
    else if (a == "--expect-markers") o.expect_markers = int_list(a, value());
    else if (a == "--param") {
      const std::string kv = value();
      const auto eq = kv.find('=');
      if (eq == std::string::npos || eq == 0) usage("--param needs NAME=VALUE, got '" + kv + "'");
      o.params.push_back({kv.substr(0, eq), number("--param " + kv.substr(0, eq), kv.substr(eq + 1), -1e300)});
    } else if (!a.empty() && a[0] == '-') usage("unknown option '" + a + "'");
    else if (o.input.empty()) o.input = a;
    else usage("more than one input: '" + o.input + "' and '" + a + "'");
  }
  if (o.input.empty()) usage("no input file");
  if (o.larger_min_dihedral && !o.cgal) usage("--check-larger-min-dihedral needs CGAL");
  return o;
}

std::string basename_no_ext(const std::string& path) {
  const auto slash = path.find_last_of('/');
  std::string b = slash == std::string::npos ? path : path.substr(slash + 1);
  const auto dot = b.find_last_of('.');
  return dot == std::string::npos ? b : b.substr(0, dot);
}

// The domain's volume, or its bounding box's when unknown: the scale of the first size guess.
double volume_scale(const Domain& d) {
  if (std::isfinite(d.volume) && d.volume > 0.0) return d.volume;
  Vec3 lo = d.vertices.at(0), hi = lo;
  for (const Vec3& v : d.vertices)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
  return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
}

struct Chosen {
  double size;
  RunResult run;
};

// Runs `mesh(size)` at sizes fitted to n(size) ~ C size^-a (a from the last two runs, 3 at
// first) until the tet count is within tol of `target`, at most max_runs times; keeps the run
// closest to the target. With `fixed` > 0 runs once at that size.
Chosen calibrate(const std::string& who, const std::function<RunResult(double)>& mesh,
                 std::size_t target, double guess, double fixed, const Options& o) {
  auto miss = [&](const RunResult& r) {
    return std::fabs(static_cast<double>(r.mesh.tets.size()) / target - 1.0);
  };
  std::optional<Chosen> best;
  double size = fixed > 0.0 ? fixed : guess, prev_size = 0.0, prev_n = 0.0;
  for (int run = 0; run < (fixed > 0.0 ? 1 : o.max_runs); ++run) {
    RunResult r = mesh(size);
    const double n = static_cast<double>(r.mesh.tets.size());
    std::printf("  %-12s size %-11.5g -> %9zu tets, %8.3f s\n", who.c_str(), size,
                r.mesh.tets.size(), r.seconds);
    std::fflush(stdout);
    const bool closer = !best || miss(r) < miss(best->run);
    const bool done = miss(r) <= o.tol;
    double a = 3.0;
    if (prev_size > 0.0 && prev_n > 0.0 && n > 0.0 && prev_size != size && prev_n != n)
      a = std::clamp(-std::log(n / prev_n) / std::log(size / prev_size), 1.5, 4.0);
    const double next = size * std::clamp(std::pow(n / target, 1.0 / a), 0.25, 4.0);
    prev_size = size;
    prev_n = n;
    if (closer) best = Chosen{size, std::move(r)};
    if (done) break;
    size = next;
  }
  return std::move(*best);
}

struct Side {
  std::string name, file_tag;
  Chosen chosen;
  Measured q;
  std::string tets_vtu, faces_vtu;
};

void print_table(const Side& ours, const Side* cgal, int repeat) {
  auto row = [&](const char* label, const std::function<std::string(const Side&)>& f) {
    std::printf("  %-24s %16s %16s\n", label, f(ours).c_str(), cgal ? f(*cgal).c_str() : "-");
  };
  auto fmt = [](const char* spec, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, spec, v);
    return std::string(buf);
  };
  std::printf("\n  %-24s %16s %16s\n", "", "slivermesh", "CGAL Mesh_3");
  row("size parameter", [&](const Side& s) { return fmt("%.5g", s.chosen.size); });
  row("vertices", [](const Side& s) { return std::to_string(s.chosen.run.mesh.points.size()); });
  row("tets", [](const Side& s) { return std::to_string(s.q.total.n_tets); });
  row("boundary triangles", [](const Side& s) { return std::to_string(s.chosen.run.mesh.faces.size()); });
  const std::string secs = repeat > 1 ? "seconds (best of " + std::to_string(repeat) + ")" : "seconds (meshing)";
  row(secs.c_str(), [&](const Side& s) { return fmt("%.3f", s.chosen.run.seconds); });
  row("tets/s", [&](const Side& s) { return fmt("%.0f", s.q.total.n_tets / s.chosen.run.seconds); });
  row("min dihedral (deg)", [&](const Side& s) { return fmt("%.2f", s.q.total.min_dihedral_deg); });
  row("max dihedral (deg)", [&](const Side& s) { return fmt("%.2f", s.q.total.max_dihedral_deg); });
  const char* below[4] = {"tets < 5 deg", "tets < 10 deg", "tets < 15 deg", "tets < 20 deg"};
  for (int k = 0; k < 4; ++k)
    row(below[k], [k](const Side& s) { return std::to_string(s.q.total.tets_below_deg[k]); });
  row("max radius-edge R/L", [&](const Side& s) { return fmt("%.3f", s.q.total.max_rho); });
  row("min sigma V/L^3", [&](const Side& s) { return fmt("%.4f", s.q.total.min_sigma); });
  row("volume", [&](const Side& s) { return fmt("%.9g", s.q.total.volume); });
  row("inverted tets", [](const Side& s) { return std::to_string(s.q.total.n_inverted); });
  row("complete", [](const Side& s) { return std::string(s.chosen.run.complete ? "yes" : "no"); });
  std::printf("\n");
}

int run(const Options& o) {
  Domain d = read_domain(o.input, o.merge);
  if (o.volume) d.volume = *o.volume;
  const std::string model = basename_no_ext(o.input);
  std::size_t n_holes = 0;
  for (const Facet& f : d.facets) n_holes += f.holes.size();
  std::printf("harness: %s: %zu vertices, %zu facets (%zu facet holes), %zu volume holes, "
              "%zu regions, volume %.9g; target %zu tets\n",
              o.input.c_str(), d.vertices.size(), d.facets.size(), n_holes, d.holes.size(),
              d.regions.size(), d.volume, o.tets);
  const double scale = volume_scale(d);
  std::vector<std::string> failures;

  Side ours{"slivermesh", "slivermesh", {}, {}, {}, {}};
  ours.chosen = calibrate(
      "slivermesh", [&](double h) { return mesh_slivermesh(d, h, o.params); }, o.tets,
      std::cbrt(5.1 * scale / o.tets), o.size, o);
  std::optional<Side> cgal;
  if (o.cgal && d.surface.empty()) {
    std::printf("  CGAL Mesh_3 not run: its polyhedral domain cannot take %s (%s)\n",
                o.input.c_str(), d.cgal_unsupported.c_str());
  } else if (o.cgal) {
    cgal = Side{"CGAL Mesh_3", "cgal", {}, {}, {}, {}};
    cgal->chosen = calibrate(
        "CGAL Mesh_3", [&](double s) { return mesh_cgal(d, s); }, ours.chosen.run.mesh.tets.size(),
        std::cbrt(4.6 * scale / ours.chosen.run.mesh.tets.size()), o.cgal_size, o);
  }
  for (int k = 1; k < o.repeat; ++k) {  // timing reruns at the chosen sizes, fastest kept
    RunResult r = mesh_slivermesh(d, ours.chosen.size, o.params);
    std::printf("  rerun %d: slivermesh %.3f s", k, r.seconds);
    if (r.seconds < ours.chosen.run.seconds) ours.chosen.run = std::move(r);
    if (cgal) {
      RunResult c = mesh_cgal(d, cgal->chosen.size);
      std::printf(", CGAL Mesh_3 %.3f s", c.seconds);
      if (c.seconds < cgal->chosen.run.seconds) cgal->chosen.run = std::move(c);
    }
    std::printf("\n");
    std::fflush(stdout);
  }

  for (Side* s : {&ours, cgal ? &*cgal : nullptr}) {
    if (!s) continue;
    s->q = measure(s->chosen.run.mesh);
    s->tets_vtu = o.outdir + "/" + model + "-" + s->file_tag + ".vtu";
    s->faces_vtu = o.outdir + "/" + model + "-" + s->file_tag + "-boundary.vtu";
    write_vtu(s->chosen.run.mesh, s->q, s->tets_vtu, s->faces_vtu);
    for (const std::string& p : check_vtu(s->chosen.run.mesh, s->q, s->tets_vtu, s->faces_vtu))
      failures.push_back(s->name + " VTK read-back: " + p);
    if (s->q.total.n_inverted)
      failures.push_back(s->name + ": " + std::to_string(s->q.total.n_inverted) +
                         " tets with volume <= 0");
  }

  std::printf("\nharness table: %s, slivermesh (%s) vs CGAL Mesh_3 (%s)", o.input.c_str(),
              ours.chosen.run.note.c_str(), cgal ? cgal->chosen.run.note.c_str() : "not run");
  print_table(ours, cgal ? &*cgal : nullptr, o.repeat);
  std::printf("VTK files: %s, %s", ours.tets_vtu.c_str(), ours.faces_vtu.c_str());
  if (cgal) std::printf(", %s, %s", cgal->tets_vtu.c_str(), cgal->faces_vtu.c_str());
  std::printf("\n");

  char buf[512];
  if (!ours.chosen.run.complete)
    failures.push_back("slivermesh did not complete (" + ours.chosen.run.note + ")");
  if (std::isfinite(d.volume)) {
    const double dev = std::fabs(ours.q.total.volume - d.volume) / d.volume;
    std::snprintf(buf, sizeof buf, "slivermesh's volume %.12g differs from the input's %.12g by %.3g%% (allowed %.3g%%)",
                  ours.q.total.volume, d.volume, 100 * dev, 100 * o.volume_tol);
    if (dev > o.volume_tol) failures.push_back(buf);
    if (cgal)
      std::printf("volume: input %.9g, slivermesh %+.3g%%, CGAL Mesh_3 %+.3g%%\n", d.volume,
                  100 * (ours.q.total.volume / d.volume - 1), 100 * (cgal->q.total.volume / d.volume - 1));
  }
  if (cgal) {
    const double ratio = static_cast<double>(ours.q.total.n_tets) / cgal->q.total.n_tets;
    std::snprintf(buf, sizeof buf, "tet counts not comparable: slivermesh %zu, CGAL %zu (ratio %.3f, allowed +-%.0f%%)",
                  ours.q.total.n_tets, cgal->q.total.n_tets, ratio, 100 * o.count_tol);
    if (std::fabs(ratio - 1.0) > o.count_tol) failures.push_back(buf);
    std::printf("min dihedral: slivermesh %.3f deg, CGAL Mesh_3 %.3f deg (difference %+.3f deg)\n",
                ours.q.total.min_dihedral_deg, cgal->q.total.min_dihedral_deg,
                ours.q.total.min_dihedral_deg - cgal->q.total.min_dihedral_deg);
    std::snprintf(buf, sizeof buf, "slivermesh's minimum dihedral angle %.3f deg is not larger than CGAL Mesh_3's %.3f deg",
                  ours.q.total.min_dihedral_deg, cgal->q.total.min_dihedral_deg);
    if (o.larger_min_dihedral && !(ours.q.total.min_dihedral_deg > cgal->q.total.min_dihedral_deg))
      failures.push_back(buf);
  }
  auto check_set = [&](const char* what, const std::vector<int32_t>& values,
                       const std::optional<std::set<int32_t>>& expected) {
    if (!expected) return;
    const std::set<int32_t> got(values.begin(), values.end());
    if (got == *expected) return;
    std::string list;
    for (int32_t v : got) list += (list.empty() ? "" : ",") + std::to_string(v);
    failures.push_back(std::string("slivermesh's ") + what + " are {" + list + "}, not the expected ones");
  };
  check_set("tet regions", ours.chosen.run.mesh.regions, o.expect_regions);
  check_set("boundary markers", ours.chosen.run.mesh.markers, o.expect_markers);
  if (o.require_min_dihedral && !(ours.q.total.min_dihedral_deg >= *o.require_min_dihedral)) {
    std::snprintf(buf, sizeof buf, "slivermesh's minimum dihedral angle %.3f deg is below the required %.3f deg",
                  ours.q.total.min_dihedral_deg, *o.require_min_dihedral);
    failures.push_back(buf);
  }
  for (const std::string& f : failures) std::printf("FAIL: %s: %s\n", model.c_str(), f.c_str());
  if (failures.empty()) std::printf("OK\n");
  return failures.empty() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse_args(argc, argv);
  try {
    return run(o);
  } catch (const std::exception& e) {
    std::printf("FAIL: %s\n", e.what());
    return 1;
  }
}
