// Tetrahedron quality measures for the ctests programs (cgal_mesh3, vtk_readback), computed with
// plain doubles from the four corner coordinates, independently of slivermesh's own code.
//
// The definitions are DESIGN.md's "Quality measures": R circumradius, L shortest edge, V volume;
// rho = R / L (regular tet: sqrt(6)/4 = 0.612), sigma = V / L^3 (regular: 1/(6 sqrt 2) = 0.1179),
// dihedral angles in degrees (regular: 70.53). V is signed: positive when (p1-p0, p2-p0, p3-p0)
// is a right-handed frame, which is VTK_TETRA's orientation and CGAL's POSITIVE orientation.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace tq {

using Vec = std::array<double, 3>;

inline Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec& a) { return std::sqrt(dot(a, a)); }

struct TetQuality {
  double volume;        // signed
  double circumradius;  // infinite for a flat tet
  double shortest_edge;
  double rho;           // circumradius / shortest_edge
  double sigma;         // |volume| / shortest_edge^3
  double min_dihedral_deg;
  double max_dihedral_deg;
};

// The dihedral angle (degrees) at edge (a, b) between the faces (a, b, c) and (a, b, d).
inline double dihedral_deg(const Vec& a, const Vec& b, const Vec& c, const Vec& d) {
  const Vec e = sub(b, a);
  const Vec nc = cross(e, sub(c, a));  // normal of face (a, b, c)
  const Vec nd = cross(e, sub(d, a));  // normal of face (a, b, d)
  // Both normals are the in-face directions towards c and d rotated by 90 degrees about the edge,
  // so the angle between them is the dihedral angle; atan2(|nc x nd|, nc . nd) keeps full accuracy
  // near 0 and 180 degrees.
  return std::atan2(norm(cross(nc, nd)), dot(nc, nd)) * (180.0 / M_PI);
}

inline TetQuality tet_quality(const Vec& p0, const Vec& p1, const Vec& p2, const Vec& p3) {
  TetQuality q{};
  const Vec a = sub(p1, p0), b = sub(p2, p0), c = sub(p3, p0);
  const double det = dot(a, cross(b, c));
  q.volume = det / 6.0;

  // |a|^2 (b x c) + |b|^2 (c x a) + |c|^2 (a x b) is 2 det times the circumcentre offset.
  const Vec bc = cross(b, c), ca = cross(c, a), ab = cross(a, b);
  const double la = dot(a, a), lb = dot(b, b), lc = dot(c, c);
  const Vec num = {la * bc[0] + lb * ca[0] + lc * ab[0], la * bc[1] + lb * ca[1] + lc * ab[1],
                   la * bc[2] + lb * ca[2] + lc * ab[2]};
  q.circumradius = det != 0.0 ? norm(num) / (2.0 * std::fabs(det))
                              : std::numeric_limits<double>::infinity();

  const Vec d12 = sub(p2, p1), d13 = sub(p3, p1), d23 = sub(p3, p2);
  const double l2 = std::min({la, lb, lc, dot(d12, d12), dot(d13, d13), dot(d23, d23)});
  q.shortest_edge = std::sqrt(l2);
  q.rho = q.circumradius / q.shortest_edge;
  q.sigma = std::fabs(q.volume) / (q.shortest_edge * l2);

  const std::array<double, 6> angles = {
      dihedral_deg(p0, p1, p2, p3), dihedral_deg(p0, p2, p1, p3), dihedral_deg(p0, p3, p1, p2),
      dihedral_deg(p1, p2, p0, p3), dihedral_deg(p1, p3, p0, p2), dihedral_deg(p2, p3, p0, p1)};
  q.min_dihedral_deg = *std::min_element(angles.begin(), angles.end());
  q.max_dihedral_deg = *std::max_element(angles.begin(), angles.end());
  return q;
}

// Whole-mesh figures, the same keys as slivermesh's --stats-json where they overlap.
struct MeshQuality {
  std::size_t n_tets = 0;
  std::size_t n_inverted = 0;  // volume <= 0
  double volume = 0.0;
  double min_dihedral_deg = 180.0;
  double max_dihedral_deg = 0.0;
  double max_rho = 0.0;
  double min_sigma = std::numeric_limits<double>::infinity();
  std::array<std::size_t, 4> tets_below_deg{};  // min dihedral below 5, 10, 15, 20 degrees

  void add(const TetQuality& q) {
    ++n_tets;
    if (!(q.volume > 0.0)) ++n_inverted;
    volume += q.volume;
    min_dihedral_deg = std::min(min_dihedral_deg, q.min_dihedral_deg);
    max_dihedral_deg = std::max(max_dihedral_deg, q.max_dihedral_deg);
    max_rho = std::max(max_rho, q.rho);
    min_sigma = std::min(min_sigma, q.sigma);
    const double limits[4] = {5.0, 10.0, 15.0, 20.0};
    for (int i = 0; i < 4; ++i)
      if (q.min_dihedral_deg < limits[i]) ++tets_below_deg[i];
  }
};

}  // namespace tq
