// The harness's input model: a piecewise linear complex as the C ABI takes it (vertices; facets
// of one outer polygon, hole polygons and a marker; volume holes; region seeds), read from .off
// or TetGen .poly by the harness itself, and the closed surface CGAL's polyhedral domain needs.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace harness {

using Vec3 = std::array<double, 3>;
using Polygon = std::vector<uint32_t>;  // 0-based vertex ids in order around the polygon

// Newell's normal of a polygon (twice its vector area).
inline Vec3 newell(const std::vector<Vec3>& v, const Polygon& p) {
  Vec3 n{0, 0, 0};
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3& a = v[p[i]];
    const Vec3& b = v[p[(i + 1) % p.size()]];
    n[0] += (a[1] - b[1]) * (a[2] + b[2]);
    n[1] += (a[2] - b[2]) * (a[0] + b[0]);
    n[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  return n;
}

struct Facet {
  Polygon outer;
  std::vector<Polygon> holes;  // sm_add_facet_hole
  int32_t marker = 1;
};

struct Region {
  Vec3 point;
  int32_t attribute;
  double max_size;  // <= 0: no limit
};

struct Domain {
  std::string path;
  std::vector<Vec3> vertices;
  std::vector<Facet> facets;
  std::vector<Vec3> holes;  // sm_add_hole seeds
  std::vector<Region> regions;
  // The boundary as polygons without holes (an .off's faces as read): CGAL's input. Empty when
  // the input cannot be given to Polyhedral_mesh_domain_3 (facet holes, volume holes, several
  // regions); cgal_unsupported then says why.
  std::vector<Polygon> surface;
  std::string cgal_unsupported;
  // Volume enclosed by the surface when it is a consistently oriented closed surface (.off),
  // NaN otherwise.
  double volume = std::numeric_limits<double>::quiet_NaN();
};

// Reads .off or .poly (by extension). With merge_coplanar, an .off's edge-adjacent, exactly
// coplanar faces become polygon facets (as `slivermesh mesh` does by default). Errors throw
// std::runtime_error naming the file and line.
Domain read_domain(const std::string& path, bool merge_coplanar);
Domain read_off(const std::string& path);
Domain read_poly(const std::string& path);

// Merges edge-adjacent, exactly coplanar facets into polygon facets, the algorithm of the
// library's plc::coplanar (markers renumbered 1, 2, ... in facet order).
void merge_coplanar_facets(Domain& d);

// Volume enclosed by an oriented closed surface (divergence theorem, polygons fanned), signed.
double enclosed_volume(const std::vector<Vec3>& vertices, const std::vector<Polygon>& polygons);

}  // namespace harness
