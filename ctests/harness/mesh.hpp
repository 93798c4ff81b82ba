// A tetrahedral mesh in flat arrays, whichever program made it, and what the harness does with
// it: measure it (one piece of code for both meshers: ctests/tet_quality.hpp), write it through
// VTK, and read the files back.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "../tet_quality.hpp"

namespace harness {

struct TetMesh {
  std::vector<tq::Vec> points;
  std::vector<std::array<int64_t, 4>> tets;  // positively oriented (VTK_TETRA's orientation)
  std::vector<int32_t> regions;              // one per tet
  std::vector<std::array<int64_t, 3>> faces;  // boundary triangles
  std::vector<int32_t> markers;               // one per boundary triangle
};

// The quality of every tet and the whole-mesh figures.
struct Measured {
  std::vector<tq::TetQuality> per_tet;
  tq::MeshQuality total;
};
Measured measure(const TetMesh& m);

// Writes the tets (cell data region, min_dihedral_deg, max_dihedral_deg, radius_edge_ratio,
// sigma) to `tets_vtu` and the boundary triangles (cell data marker) to `faces_vtu`, binary
// vtkXMLUnstructuredGridWriter files. Throws on failure.
void write_vtu(const TetMesh& m, const Measured& q, const std::string& tets_vtu,
               const std::string& faces_vtu);

// Reads both files back with vtkXMLUnstructuredGridReader and compares them with `m`: point and
// cell counts, cell types, every cell data array present with one value per cell, the regions
// and markers, and the minimum dihedral angle re-measured from the read coordinates. Returns the
// problems found (empty: the files are right).
std::vector<std::string> check_vtu(const TetMesh& m, const Measured& q,
                                   const std::string& tets_vtu, const std::string& faces_vtu);

}  // namespace harness
