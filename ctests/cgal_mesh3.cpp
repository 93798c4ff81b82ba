// cgal_mesh3: the CGAL Mesh_3 reference for slivermesh's quality meshing (issue 5, "the CGAL
// harness"), and a VTK-based measurer so both meshes are judged by the same code.
//
//   cgal_mesh3 mesh INPUT.off --size H [--edge-size E] [--facet-size F] [--facet-distance D]
//              [--facet-angle 25] [--radius-edge 2] [--feature-angle 60] [--no-perturb]
//              [--no-exude] [--vtu OUT.vtu]
//     Meshes the polyhedron with Polyhedral_mesh_domain_with_features_3 (detect_features(A):
//     an edge is a feature when its two faces' normals differ by more than A degrees, default
//     CGAL's 60),
//     Mesh_criteria_3 (edge_size, facet_angle, facet_size, facet_distance,
//     cell_radius_edge_ratio, cell_size) and make_mesh_3 with perturb() and exude() (CGAL's
//     defaults: no time limit, no target bound, so both optimisers run as long as they improve the
//     smallest dihedral angle). The sizes default to H (cell_size bounds the circumradius, like
//     slivermesh's --size) and the facet distance to H / 10. Single-threaded (Sequential_tag), with
//     CGAL's default random generator, so a run is deterministic.
//
//   cgal_mesh3 measure MESH.vtu [--vtu OUT.vtu]
//     Reads a tetrahedral .vtu (e.g. written by `slivermesh mesh`) with VTK and measures it.
//
// Both print one JSON object on stdout: n_vertices, n_tets, the seconds (mesh mode), the quality
// figures (min/max dihedral, max radius-edge ratio, min sigma = V/L^3, tets below 5/10/15/20
// degrees, inverted tets, volume); with --vtu they also write the mesh through VTK
// (vtkXMLUnstructuredGridWriter) with cell data region, radius_edge_ratio, sigma,
// min_dihedral_deg and max_dihedral_deg. Errors go to stderr with exit status 1 (2 for usage).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_polyhedron_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/make_mesh_3.h>
#include <CGAL/version.h>

#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "tet_quality.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Polyhedron = CGAL::Mesh_polyhedron_3<K>::type;
using Mesh_domain = CGAL::Polyhedral_mesh_domain_with_features_3<K>;
using Tr = CGAL::Mesh_triangulation_3<Mesh_domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Mesh_domain::Corner_index,
                                                     Mesh_domain::Curve_index>;
using Mesh_criteria = CGAL::Mesh_criteria_3<Tr>;
namespace params = CGAL::parameters;

// A tetrahedral mesh in flat arrays: what both modes measure and write.
struct TetMesh {
  std::vector<tq::Vec> points;
  std::vector<std::array<vtkIdType, 4>> tets;
  std::vector<int> regions;
};

struct Options {
  std::string mode, input, vtu_out;
  double size = 0.0, edge_size = 0.0, facet_size = 0.0, facet_distance = 0.0;
  double facet_angle = 25.0, radius_edge = 2.0, feature_angle = 60.0;
  bool perturb = true, exude = true;
};

[[noreturn]] void usage(const std::string& why) {
  std::cerr << "error: " << why << "\n"
            << "usage: cgal_mesh3 mesh INPUT.off --size H [--edge-size E] [--facet-size F]\n"
            << "                  [--facet-distance D] [--facet-angle DEG] [--radius-edge R]\n"
            << "                  [--feature-angle DEG] [--no-perturb] [--no-exude] [--vtu OUT.vtu]\n"
            << "       cgal_mesh3 measure MESH.vtu [--vtu OUT.vtu]\n";
  std::exit(2);
}

double parse_positive(const std::string& flag, const char* text) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(v > 0.0) || !std::isfinite(v))
    usage(flag + " needs a finite positive number, got '" + text + "'");
  return v;
}

Options parse_args(int argc, char** argv) {
  Options o;
  if (argc < 3) usage("need a mode (mesh or measure) and an input file");
  o.mode = argv[1];
  o.input = argv[2];
  if (o.mode != "mesh" && o.mode != "measure") usage("unknown mode '" + o.mode + "'");
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) usage(a + " needs a value");
      return argv[++i];
    };
    if (a == "--vtu") o.vtu_out = value();
    else if (a == "--size") o.size = parse_positive(a, value());
    else if (a == "--edge-size") o.edge_size = parse_positive(a, value());
    else if (a == "--facet-size") o.facet_size = parse_positive(a, value());
    else if (a == "--facet-distance") o.facet_distance = parse_positive(a, value());
    else if (a == "--facet-angle") o.facet_angle = parse_positive(a, value());
    else if (a == "--radius-edge") o.radius_edge = parse_positive(a, value());
    else if (a == "--feature-angle") o.feature_angle = parse_positive(a, value());
    else if (a == "--no-perturb") o.perturb = false;
    else if (a == "--no-exude") o.exude = false;
    else usage("unknown option '" + a + "'");
  }
  if (o.mode == "mesh") {
    if (o.size <= 0.0) usage("mesh mode needs --size H");
    if (o.edge_size <= 0.0) o.edge_size = o.size;
    if (o.facet_size <= 0.0) o.facet_size = o.size;
    if (o.facet_distance <= 0.0) o.facet_distance = o.size / 10.0;
  }
  return o;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// make_mesh_3 takes the optimiser switches as differently typed named parameters.
template <typename Perturb, typename Exude>
C3t3 run_mesh_3(const Mesh_domain& domain, const Mesh_criteria& criteria, const Perturb& p,
                const Exude& e) {
  return CGAL::make_mesh_3<C3t3>(domain, criteria, params::no_lloyd(), params::no_odt(), p, e);
}

TetMesh extract(const C3t3& c3t3) {
  TetMesh m;
  std::unordered_map<Tr::Vertex_handle, vtkIdType> index;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    std::array<vtkIdType, 4> tet{};
    for (int i = 0; i < 4; ++i) {
      const Tr::Vertex_handle v = c->vertex(i);
      auto it = index.find(v);
      if (it == index.end()) {
        const auto& p = v->point().point();  // the weighted point's bare point
        it = index.emplace(v, static_cast<vtkIdType>(m.points.size())).first;
        m.points.push_back({CGAL::to_double(p.x()), CGAL::to_double(p.y()),
                            CGAL::to_double(p.z())});
      }
      tet[i] = it->second;
    }
    m.tets.push_back(tet);
    m.regions.push_back(static_cast<int>(c3t3.subdomain_index(c)));
  }
  return m;
}

TetMesh read_vtu(const std::string& path) {
  std::ifstream probe(path);
  if (!probe) throw std::runtime_error("cannot open " + path);
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkUnstructuredGrid* ug = reader->GetOutput();
  if (ug == nullptr || ug->GetNumberOfPoints() == 0)
    throw std::runtime_error(path + ": VTK read no points (not an UnstructuredGrid .vtu?)");
  TetMesh m;
  for (vtkIdType i = 0; i < ug->GetNumberOfPoints(); ++i) {
    double p[3];
    ug->GetPoint(i, p);
    m.points.push_back({p[0], p[1], p[2]});
  }
  vtkDataArray* region = ug->GetCellData()->GetArray("region");
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < ug->GetNumberOfCells(); ++c) {
    if (ug->GetCellType(c) != VTK_TETRA)
      throw std::runtime_error(path + ": cell " + std::to_string(c) + " is not a VTK_TETRA");
    ug->GetCellPoints(c, ids);
    m.tets.push_back({ids->GetId(0), ids->GetId(1), ids->GetId(2), ids->GetId(3)});
    m.regions.push_back(region ? static_cast<int>(region->GetTuple1(c)) : 0);
  }
  return m;
}

tq::MeshQuality measure(const TetMesh& m, std::vector<tq::TetQuality>* per_tet) {
  tq::MeshQuality mq;
  for (const auto& t : m.tets) {
    const tq::TetQuality q =
        tq::tet_quality(m.points[t[0]], m.points[t[1]], m.points[t[2]], m.points[t[3]]);
    mq.add(q);
    if (per_tet) per_tet->push_back(q);
  }
  return mq;
}

void write_vtu(const TetMesh& m, const std::vector<tq::TetQuality>& q, const std::string& path) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(m.points.size()));
  for (std::size_t i = 0; i < m.points.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), m.points[i].data());
  vtkNew<vtkUnstructuredGrid> ug;
  ug->SetPoints(points);
  ug->Allocate(static_cast<vtkIdType>(m.tets.size()));
  for (const auto& t : m.tets) ug->InsertNextCell(VTK_TETRA, 4, t.data());

  const vtkIdType n = static_cast<vtkIdType>(m.tets.size());
  vtkNew<vtkIntArray> region;
  region->SetName("region");
  region->SetNumberOfTuples(n);
  auto make = [n](const char* name) {
    vtkDoubleArray* a = vtkDoubleArray::New();
    a->SetName(name);
    a->SetNumberOfTuples(n);
    return a;
  };
  vtkDoubleArray* rho = make("radius_edge_ratio");
  vtkDoubleArray* sigma = make("sigma");
  vtkDoubleArray* dmin = make("min_dihedral_deg");
  vtkDoubleArray* dmax = make("max_dihedral_deg");
  for (vtkIdType c = 0; c < n; ++c) {
    region->SetValue(c, m.regions[c]);
    rho->SetValue(c, q[c].rho);
    sigma->SetValue(c, q[c].sigma);
    dmin->SetValue(c, q[c].min_dihedral_deg);
    dmax->SetValue(c, q[c].max_dihedral_deg);
  }
  ug->GetCellData()->AddArray(region);
  for (vtkDoubleArray* a : {rho, sigma, dmin, dmax}) {
    ug->GetCellData()->AddArray(a);
    a->Delete();  // the cell data holds a reference
  }

  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetFileName(path.c_str());
  writer->SetInputData(ug);
  writer->SetDataModeToBinary();
  if (writer->Write() != 1) throw std::runtime_error("VTK could not write " + path);
}

void print_json(const Options& o, const TetMesh& m, const tq::MeshQuality& mq,
                const std::string& timings) {
  std::printf("{\n  \"program\": \"%s\",\n  \"input\": \"%s\",\n",
              o.mode == "mesh" ? "CGAL Mesh_3 " CGAL_VERSION_STR : "measure", o.input.c_str());
  if (o.mode == "mesh")
    std::printf("  \"size\": %.17g,\n  \"edge_size\": %.17g,\n  \"facet_size\": %.17g,\n"
                "  \"facet_distance\": %.17g,\n  \"facet_angle\": %.17g,\n"
                "  \"cell_radius_edge_ratio\": %.17g,\n  \"feature_angle\": %.17g,\n"
                "  \"perturb\": %s,\n  \"exude\": %s,\n",
                o.size, o.edge_size, o.facet_size, o.facet_distance, o.facet_angle,
                o.radius_edge, o.feature_angle, o.perturb ? "true" : "false", o.exude ? "true" : "false");
  std::printf("%s", timings.c_str());
  std::printf("  \"n_vertices\": %zu,\n  \"n_tets\": %zu,\n  \"n_inverted\": %zu,\n"
              "  \"volume\": %.17g,\n  \"min_dihedral_deg\": %.17g,\n"
              "  \"max_dihedral_deg\": %.17g,\n  \"max_rho\": %.17g,\n  \"min_sigma\": %.17g,\n"
              "  \"tets_below_deg\": [%zu, %zu, %zu, %zu]\n}\n",
              m.points.size(), mq.n_tets, mq.n_inverted, mq.volume, mq.min_dihedral_deg,
              mq.max_dihedral_deg, mq.max_rho, mq.min_sigma, mq.tets_below_deg[0],
              mq.tets_below_deg[1], mq.tets_below_deg[2], mq.tets_below_deg[3]);
}

int run(const Options& o) {
  TetMesh m;
  char timings[512] = "";
  if (o.mode == "mesh") {
    const auto t0 = std::chrono::steady_clock::now();
    Polyhedron polyhedron;
    {
      std::ifstream in(o.input);
      if (!in) throw std::runtime_error("cannot open " + o.input);
      if (!(in >> polyhedron) || polyhedron.empty())
        throw std::runtime_error(o.input + ": not a readable OFF polyhedron");
    }
    if (!CGAL::is_triangle_mesh(polyhedron))
      throw std::runtime_error(o.input + ": Polyhedral_mesh_domain needs a triangle mesh");
    const double t_read = seconds_since(t0);

    const auto t1 = std::chrono::steady_clock::now();
    Mesh_domain domain(polyhedron);
    domain.detect_features(o.feature_angle);
    Mesh_criteria criteria(params::edge_size = o.edge_size, params::facet_angle = o.facet_angle,
                           params::facet_size = o.facet_size,
                           params::facet_distance = o.facet_distance,
                           params::cell_radius_edge_ratio = o.radius_edge,
                           params::cell_size = o.size);
    C3t3 c3t3;
    if (o.perturb && o.exude)
      c3t3 = run_mesh_3(domain, criteria, params::perturb(), params::exude());
    else if (o.perturb)
      c3t3 = run_mesh_3(domain, criteria, params::perturb(), params::no_exude());
    else if (o.exude)
      c3t3 = run_mesh_3(domain, criteria, params::no_perturb(), params::exude());
    else
      c3t3 = run_mesh_3(domain, criteria, params::no_perturb(), params::no_exude());
    const double t_mesh = seconds_since(t1);
    m = extract(c3t3);
    std::snprintf(timings, sizeof timings,
                  "  \"seconds_read\": %.6f,\n  \"seconds_total\": %.6f,\n", t_read, t_mesh);
  } else {
    m = read_vtu(o.input);
  }
  if (m.tets.empty()) throw std::runtime_error(o.input + ": the mesh has no tetrahedra");

  std::vector<tq::TetQuality> per_tet;
  const tq::MeshQuality mq = measure(m, o.vtu_out.empty() ? nullptr : &per_tet);
  if (!o.vtu_out.empty()) write_vtu(m, per_tet, o.vtu_out);
  print_json(o, m, mq, timings);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse_args(argc, argv);
  try {
    return run(o);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}
