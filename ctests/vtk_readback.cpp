// vtk_readback: reads a .vtu written by `slivermesh mesh` with VTK's own reader and checks it
// against the run's --stats-json report (issue 3: "the .vtu also read back by VTK").
//
//   vtk_readback MESH.vtu STATS.json [--regions 1,2] [--volume V]
//
// Checks, each failure printed as "FAIL: ..." (exit status 1; 2 for usage errors):
//  * the number of points and cells equal the report's n_vertices and n_tets;
//  * every cell is a VTK_TETRA with positive volume (VTK's orientation: p3 on the side of
//    (p0, p1, p2) that its right-hand normal points to), and the volumes sum to --volume;
//  * the cell data has "region" (one component, one value per cell; with --regions the set of
//    values present is exactly that list) and the quality arrays radius_edge_ratio, sigma,
//    min_dihedral_deg, each agreeing with the value recomputed here from the coordinates, and their
//    extremes with the report's max_rho, min_sigma, min_dihedral_deg.
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkType.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>

#include "tet_quality.hpp"

namespace {

int failures = 0;

void fail(const std::string& msg) {
  std::printf("FAIL: %s\n", msg.c_str());
  ++failures;
}

[[noreturn]] void usage(const std::string& why) {
  std::cerr << "error: " << why << "\n"
            << "usage: vtk_readback MESH.vtu STATS.json [--regions 1,2] [--volume V]\n";
  std::exit(2);
}

// The number after "key": in a flat JSON object (the stats report has no nesting we need).
bool json_number(const std::string& json, const std::string& key, double* out) {
  const std::size_t k = json.find("\"" + key + "\"");
  if (k == std::string::npos) return false;
  const std::size_t colon = json.find(':', k);
  if (colon == std::string::npos) return false;
  const char* start = json.c_str() + colon + 1;
  char* end = nullptr;
  *out = std::strtod(start, &end);
  return end != start;
}

bool close(double a, double b, double rel) {
  return std::fabs(a - b) <= rel * std::max(1.0, std::max(std::fabs(a), std::fabs(b)));
}

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) usage("need MESH.vtu and STATS.json");
  const std::string vtu = argv[1], stats_path = argv[2];
  std::set<int> want_regions;
  bool check_regions = false;
  double want_volume = -1.0;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) usage(a + " needs a value");
    const std::string v = argv[++i];
    if (a == "--regions") {
      check_regions = true;
      std::stringstream ss(v);
      std::string item;
      while (std::getline(ss, item, ',')) want_regions.insert(std::atoi(item.c_str()));
    } else if (a == "--volume") {
      want_volume = std::atof(v.c_str());
    } else {
      usage("unknown option '" + a + "'");
    }
  }

  std::ifstream sf(stats_path);
  if (!sf) usage("cannot open " + stats_path);
  const std::string stats((std::istreambuf_iterator<char>(sf)), std::istreambuf_iterator<char>());
  double n_vertices = 0, n_tets = 0, max_rho = 0, min_sigma = 0, min_dihedral = 0;
  if (!json_number(stats, "n_vertices", &n_vertices) || !json_number(stats, "n_tets", &n_tets) ||
      !json_number(stats, "max_rho", &max_rho) || !json_number(stats, "min_sigma", &min_sigma) ||
      !json_number(stats, "min_dihedral_deg", &min_dihedral)) {
    std::printf("FAIL: %s lacks n_vertices / n_tets / max_rho / min_sigma / min_dihedral_deg\n",
                stats_path.c_str());
    return 1;
  }

  // With --order 2 the report names the mid-edge nodes: the points are the vertices and those,
  // the cells VTK_QUADRATIC_TETRA (corners first, as the linear tet).
  double n_edge_nodes = 0;
  const bool quadratic = json_number(stats, "n_edge_nodes", &n_edge_nodes);
  const int want_type = quadratic ? VTK_QUADRATIC_TETRA : VTK_TETRA;
  const std::string want_name = quadratic ? "VTK_QUADRATIC_TETRA (24)" : "VTK_TETRA (10)";

  if (!std::ifstream(vtu)) usage("cannot open " + vtu);
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(vtu.c_str());
  reader->Update();
  vtkUnstructuredGrid* ug = reader->GetOutput();
  const vtkIdType np = ug ? ug->GetNumberOfPoints() : 0, nc = ug ? ug->GetNumberOfCells() : 0;
  std::printf("%s: %lld points, %lld cells (report: %.0f vertices, %.0f tets)\n", vtu.c_str(),
              static_cast<long long>(np), static_cast<long long>(nc), n_vertices, n_tets);
  if (np != static_cast<vtkIdType>(n_vertices + n_edge_nodes))
    fail("VTK read " + std::to_string(np) + " points, the report says " +
         fmt(n_vertices + n_edge_nodes));
  if (nc != static_cast<vtkIdType>(n_tets))
    fail("VTK read " + std::to_string(nc) + " cells, the report says " + fmt(n_tets));
  if (nc == 0) {
    fail("no cells to check");
    return 1;
  }

  vtkCellData* cd = ug->GetCellData();
  auto array = [&](const char* name) -> vtkDataArray* {
    vtkDataArray* a = cd->GetArray(name);
    if (a == nullptr) {
      fail(std::string("cell data array \"") + name + "\" is missing");
    } else if (a->GetNumberOfComponents() != 1 || a->GetNumberOfTuples() != nc) {
      fail(std::string("cell data array \"") + name + "\" has " +
           std::to_string(a->GetNumberOfTuples()) + " tuples of " +
           std::to_string(a->GetNumberOfComponents()) + " components, want " +
           std::to_string(nc) + " of 1");
      a = nullptr;
    }
    return a;
  };
  vtkDataArray* region = array("region");
  vtkDataArray* rho = array("radius_edge_ratio");
  vtkDataArray* sigma = array("sigma");
  vtkDataArray* dmin = array("min_dihedral_deg");
  if (region && (region->GetDataType() == VTK_FLOAT || region->GetDataType() == VTK_DOUBLE))
    fail(std::string("\"region\" is a ") + region->GetDataTypeAsString() + " array, not integral");

  // Per-cell checks; report the first few of each kind, then count.
  std::size_t not_tetra = 0, not_positive = 0, rho_off = 0, sigma_off = 0, dmin_off = 0;
  const std::size_t show = 3;
  tq::MeshQuality mq;
  double arr_max_rho = 0, arr_min_sigma = INFINITY, arr_min_dihedral = INFINITY;
  std::set<int> regions;
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < nc; ++c) {
    if (ug->GetCellType(c) != want_type) {
      if (not_tetra++ < show)
        fail("cell " + std::to_string(c) + " has VTK type " + std::to_string(ug->GetCellType(c)) +
             ", not " + want_name);
      continue;
    }
    ug->GetCellPoints(c, ids);
    tq::Vec p[4];
    for (int i = 0; i < 4; ++i) ug->GetPoint(ids->GetId(i), p[i].data());
    const tq::TetQuality q = tq::tet_quality(p[0], p[1], p[2], p[3]);
    mq.add(q);
    if (!(q.volume > 0.0) && not_positive++ < show)
      fail("cell " + std::to_string(c) + " has volume " + fmt(q.volume) + " <= 0");
    if (region) regions.insert(static_cast<int>(region->GetTuple1(c)));
    // The arrays are written in ASCII with shortest round-trip formatting, so they agree with a
    // recomputation up to the rounding of different but equivalent formulas.
    if (rho) {
      const double v = rho->GetTuple1(c);
      arr_max_rho = std::max(arr_max_rho, v);
      if (!close(v, q.rho, 1e-6) && rho_off++ < show)
        fail("cell " + std::to_string(c) + ": radius_edge_ratio " + fmt(v) + ", recomputed " +
             fmt(q.rho));
    }
    if (sigma) {
      const double v = sigma->GetTuple1(c);
      arr_min_sigma = std::min(arr_min_sigma, v);
      if (!close(v, q.sigma, 1e-6) && sigma_off++ < show)
        fail("cell " + std::to_string(c) + ": sigma " + fmt(v) + ", recomputed " + fmt(q.sigma));
    }
    if (dmin) {
      const double v = dmin->GetTuple1(c);
      arr_min_dihedral = std::min(arr_min_dihedral, v);
      if (!close(v, q.min_dihedral_deg, 1e-6) && dmin_off++ < show)
        fail("cell " + std::to_string(c) + ": min_dihedral_deg " + fmt(v) + ", recomputed " +
             fmt(q.min_dihedral_deg));
    }
  }
  auto count = [&](std::size_t n, const char* what) {
    if (n > show) fail(std::to_string(n) + " cells in all " + what);
  };
  count(not_tetra, ("are not " + want_name).c_str());
  count(not_positive, "have volume <= 0");
  count(rho_off, "disagree on radius_edge_ratio");
  count(sigma_off, "disagree on sigma");
  count(dmin_off, "disagree on min_dihedral_deg");

  if (rho && !close(arr_max_rho, max_rho, 1e-6))
    fail("max radius_edge_ratio in the file " + fmt(arr_max_rho) + ", report max_rho " +
         fmt(max_rho));
  if (sigma && !close(arr_min_sigma, min_sigma, 1e-6))
    fail("min sigma in the file " + fmt(arr_min_sigma) + ", report min_sigma " + fmt(min_sigma));
  if (dmin && !close(arr_min_dihedral, min_dihedral, 1e-6))
    fail("min min_dihedral_deg in the file " + fmt(arr_min_dihedral) +
         ", report min_dihedral_deg " + fmt(min_dihedral));

  std::string present;
  for (int r : regions) present += (present.empty() ? "" : ",") + std::to_string(r);
  if (check_regions && regions != want_regions) {
    std::string want;
    for (int r : want_regions) want += (want.empty() ? "" : ",") + std::to_string(r);
    fail("regions present {" + present + "}, expected {" + want + "}");
  }
  if (want_volume > 0.0 && !close(mq.volume, want_volume, 1e-9))
    fail("tet volumes sum to " + fmt(mq.volume) + ", expected " + fmt(want_volume));

  std::printf("regions {%s}; volume %.12g; min/max dihedral %.4f / %.4f deg; max rho %.4f; "
              "min sigma %.4f\n",
              present.c_str(), mq.volume, mq.min_dihedral_deg, mq.max_dihedral_deg, mq.max_rho,
              mq.min_sigma);
  if (failures) {
    std::printf("%d check(s) failed\n", failures);
    return 1;
  }
  std::printf("PASS: VTK read the mesh back and every check holds\n");
  return 0;
}
