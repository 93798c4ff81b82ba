// slivermesh through its C ABI (see meshers.hpp): what a C++ FEM code linking libslivermesh does.
#include <slivermesh.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "meshers.hpp"

namespace harness {
namespace {

// Owns an sm_mesher; a failing call throws with the library's message.
class Mesher {
 public:
  Mesher() : m_(sm_create(), &sm_destroy) {
    if (!m_) throw std::bad_alloc();
  }
  sm_mesher* get() const { return m_.get(); }
  void check(sm_status s, const std::string& what) const {
    if (s != SM_OK)
      throw std::runtime_error(what + ": " + sm_status_str(s) + ": " + sm_last_error(m_.get()));
  }
  // Registers a functor double(double, double, double) as the spacing; it must outlive every
  // sm_refine on this handle. No exception may cross the C boundary: one becomes NaN, which
  // sm_refine reports as SM_ERR_SPACING naming the point.
  template <typename F>
  void set_spacing(F& f) {
    check(sm_set_spacing_cb(m_.get(), &trampoline<F>, &f), "sm_set_spacing_cb");
  }

 private:
  template <typename F>
  static double trampoline(double x, double y, double z, void* user_data) noexcept {
    try {
      return (*static_cast<F*>(user_data))(x, y, z);
    } catch (...) {
      return std::numeric_limits<double>::quiet_NaN();
    }
  }
  std::unique_ptr<sm_mesher, decltype(&sm_destroy)> m_;
};

// The spacing the harness asks for: h everywhere, counting its calls.
struct UniformSpacing {
  double h;
  std::size_t calls = 0;
  double operator()(double, double, double) {
    ++calls;
    return h;
  }
};

}  // namespace

RunResult mesh_slivermesh(const Domain& d, double h,
                          const std::vector<std::pair<std::string, double>>& params) {
  Mesher m;
  std::vector<double> xyz;
  for (const Vec3& v : d.vertices) xyz.insert(xyz.end(), v.begin(), v.end());
  m.check(sm_add_vertices(m.get(), xyz.data(), d.vertices.size()), "sm_add_vertices");
  for (std::size_t i = 0; i < d.facets.size(); ++i) {
    const Facet& f = d.facets[i];
    const std::string name = "facet " + std::to_string(i);
    m.check(sm_add_facet(m.get(), f.outer.data(), f.outer.size(), f.marker), "sm_add_facet " + name);
    for (const Polygon& hole : f.holes)
      m.check(sm_add_facet_hole(m.get(), hole.data(), hole.size()), "sm_add_facet_hole " + name);
  }
  for (const Vec3& p : d.holes) m.check(sm_add_hole(m.get(), p[0], p[1], p[2]), "sm_add_hole");
  for (const Region& r : d.regions)
    m.check(sm_add_region(m.get(), r.point[0], r.point[1], r.point[2], r.attribute, r.max_size),
            "sm_add_region");
  for (const auto& [name, value] : params)
    m.check(sm_set_param(m.get(), name.c_str(), value), "sm_set_param " + name);
  UniformSpacing spacing{h};
  m.set_spacing(spacing);

  const auto t0 = std::chrono::steady_clock::now();
  m.check(sm_refine(m.get()), "sm_refine");
  RunResult r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const std::size_t nv = sm_num_vertices(m.get()), nt = sm_num_tets(m.get()),
                    nf = sm_num_boundary_faces(m.get());
  std::vector<double> pts(3 * nv);
  m.check(sm_get_vertices(m.get(), pts.data(), nv), "sm_get_vertices");
  std::vector<uint32_t> tets(4 * nt), tris(3 * nf);
  r.mesh.regions.resize(nt);
  r.mesh.markers.resize(nf);
  m.check(sm_get_tets(m.get(), tets.data(), r.mesh.regions.data(), nt), "sm_get_tets");
  m.check(sm_get_boundary_faces(m.get(), tris.data(), r.mesh.markers.data(), nf),
          "sm_get_boundary_faces");
  for (std::size_t i = 0; i < nv; ++i) r.mesh.points.push_back({pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]});
  for (std::size_t t = 0; t < nt; ++t)
    r.mesh.tets.push_back({tets[4 * t], tets[4 * t + 1], tets[4 * t + 2], tets[4 * t + 3]});
  for (std::size_t f = 0; f < nf; ++f)
    r.mesh.faces.push_back({tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]});

  sm_quality q{};
  m.check(sm_get_quality(m.get(), &q), "sm_get_quality");
  r.complete = q.complete != 0;
  const char* stop = sm_stop_reason(m.get());
  r.note = "slivermesh " + std::string(sm_version()) + ", " + std::to_string(spacing.calls) +
           " spacing calls" + (stop ? std::string(", stopped: ") + stop : std::string());
  return r;
}

}  // namespace harness
