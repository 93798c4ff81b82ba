// CGAL Mesh_3, the reference (see meshers.hpp). The same criteria as ctests/cgal_mesh3.cpp.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_polyhedron_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/make_mesh_3.h>
#include <CGAL/version.h>

#include <chrono>
#include <stdexcept>
#include <unordered_map>

#include "meshers.hpp"

namespace harness {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Polyhedron = CGAL::Mesh_polyhedron_3<K>::type;
using Mesh_domain = CGAL::Polyhedral_mesh_domain_with_features_3<K>;
using Tr = CGAL::Mesh_triangulation_3<Mesh_domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Mesh_domain::Corner_index,
                                                     Mesh_domain::Curve_index>;
using Mesh_criteria = CGAL::Mesh_criteria_3<Tr>;
namespace params = CGAL::parameters;
namespace PMP = CGAL::Polygon_mesh_processing;

Polyhedron polyhedron_of(const Domain& d) {
  if (d.surface.empty())
    throw std::runtime_error("CGAL's polyhedral domain cannot take this input (" +
                             (d.cgal_unsupported.empty() ? std::string("no surface")
                                                         : d.cgal_unsupported) +
                             ")");
  std::vector<K::Point_3> points;
  for (const Vec3& v : d.vertices) points.emplace_back(v[0], v[1], v[2]);
  std::vector<std::vector<std::size_t>> polygons;
  for (const Polygon& p : d.surface) polygons.emplace_back(p.begin(), p.end());
  PMP::orient_polygon_soup(points, polygons);  // .poly facets come in any orientation
  Polyhedron poly;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, poly);
  if (!CGAL::is_triangle_mesh(poly)) PMP::triangulate_faces(poly);
  if (poly.empty() || !CGAL::is_closed(poly))
    throw std::runtime_error(d.path + ": not a closed surface CGAL's polyhedral domain can take");
  return poly;
}

TetMesh extract(const C3t3& c3t3) {
  TetMesh m;
  std::unordered_map<Tr::Vertex_handle, int64_t> index;
  auto id = [&](Tr::Vertex_handle v) {
    auto it = index.find(v);
    if (it == index.end()) {
      const auto& p = v->point().point();  // the weighted point's bare point
      it = index.emplace(v, static_cast<int64_t>(m.points.size())).first;
      m.points.push_back({CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())});
    }
    return it->second;
  };
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    m.tets.push_back({id(c->vertex(0)), id(c->vertex(1)), id(c->vertex(2)), id(c->vertex(3))});
    m.regions.push_back(static_cast<int32_t>(c3t3.subdomain_index(c)));
  }
  const Tr& tr = c3t3.triangulation();
  for (auto f = c3t3.facets_in_complex_begin(); f != c3t3.facets_in_complex_end(); ++f) {
    Tr::Cell_handle c = f->first;
    int i = f->second;
    if (!c3t3.is_in_complex(c)) {  // look from the meshed side
      const Tr::Facet mirror = tr.mirror_facet(*f);
      c = mirror.first;
      i = mirror.second;
    }
    // Outward: the cell's own vertex i (inside) on the negative side of (a, b, c).
    std::array<Tr::Vertex_handle, 3> v{};
    for (int k = 0, j = 0; k < 4; ++k)
      if (k != i) v[j++] = c->vertex(k);
    if (CGAL::orientation(v[0]->point().point(), v[1]->point().point(), v[2]->point().point(),
                          c->vertex(i)->point().point()) == CGAL::POSITIVE)
      std::swap(v[1], v[2]);
    const std::array<int64_t, 3> tri{id(v[0]), id(v[1]), id(v[2])};
    m.faces.push_back(tri);
    m.markers.push_back(static_cast<int32_t>(c3t3.surface_patch_index(*f)));
  }
  return m;
}

}  // namespace

RunResult mesh_cgal(const Domain& d, double s) {
  const Polyhedron poly = polyhedron_of(d);
  const auto t0 = std::chrono::steady_clock::now();
  Mesh_domain domain(poly);
  domain.detect_features();
  const Mesh_criteria criteria(params::edge_size = s, params::facet_angle = 25.0,
                               params::facet_size = s, params::facet_distance = s / 10.0,
                               params::cell_radius_edge_ratio = 2.0, params::cell_size = s);
  const C3t3 c3t3 = CGAL::make_mesh_3<C3t3>(domain, criteria, params::no_lloyd(),
                                             params::no_odt(), params::perturb(), params::exude());
  RunResult r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.mesh = extract(c3t3);
  r.note = "CGAL " CGAL_VERSION_STR;
  return r;
}

}  // namespace harness
