// The two meshers under comparison, behind one call each: the input Domain and a size in, a
// TetMesh (tets, regions, boundary triangles, markers) and the meshing time out.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "domain.hpp"
#include "mesh.hpp"

namespace harness {

struct RunResult {
  TetMesh mesh;
  double seconds = 0.0;   // meshing only (sm_refine; CGAL's domain, features and make_mesh_3)
  bool complete = true;   // slivermesh: every bound holds where it is enforced
  std::string note;       // slivermesh: stop reason, spacing calls; CGAL: version
};

// slivermesh through its C ABI: sm_add_vertices / sm_add_facet / sm_add_facet_hole / sm_add_hole
// / sm_add_region, a constant spacing `h` given as a C++ functor through sm_set_spacing_cb's
// user_data, `params` through sm_set_param, sm_refine, then sm_get_vertices / sm_get_tets /
// sm_get_boundary_faces. Throws with the library's message on any failing call.
RunResult mesh_slivermesh(const Domain& d, double h,
                          const std::vector<std::pair<std::string, double>>& params);

// CGAL Mesh_3 on d.surface: Polyhedral_mesh_domain_with_features_3 with detect_features(),
// edge, facet and cell size `s`, facet distance s/10, facet angle 25, cell radius-edge ratio 2,
// make_mesh_3 with perturb() and exude() (no Lloyd/ODT), sequential. Regions are CGAL's
// subdomain indices, markers its surface patch indices. Throws when d.surface is empty.
RunResult mesh_cgal(const Domain& d, double s);

}  // namespace harness
