// Measuring a TetMesh and its VTK files (see mesh.hpp).
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <fstream>
#include <stdexcept>

#include "mesh.hpp"

namespace harness {
namespace {

vtkSmartPointer<vtkPoints> make_points(const TetMesh& m) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(m.points.size()));
  for (std::size_t i = 0; i < m.points.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), m.points[i].data());
  return points;
}

template <typename Array, typename F>
void add_array(vtkUnstructuredGrid* ug, const char* name, std::size_t n, F value) {
  vtkNew<Array> a;
  a->SetName(name);
  a->SetNumberOfTuples(static_cast<vtkIdType>(n));
  for (std::size_t c = 0; c < n; ++c) a->SetValue(static_cast<vtkIdType>(c), value(c));
  ug->GetCellData()->AddArray(a);
}

void write(vtkUnstructuredGrid* ug, const std::string& path) {
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetFileName(path.c_str());
  writer->SetInputData(ug);
  writer->SetDataModeToBinary();
  if (writer->Write() != 1) throw std::runtime_error("VTK could not write " + path);
}

vtkUnstructuredGrid* read(vtkXMLUnstructuredGridReader* reader, const std::string& path) {
  if (!std::ifstream(path)) return nullptr;
  reader->SetFileName(path.c_str());
  reader->Update();
  return reader->GetOutput();
}

}  // namespace

Measured measure(const TetMesh& m) {
  Measured r;
  r.per_tet.reserve(m.tets.size());
  for (const auto& t : m.tets) {
    r.per_tet.push_back(
        tq::tet_quality(m.points[t[0]], m.points[t[1]], m.points[t[2]], m.points[t[3]]));
    r.total.add(r.per_tet.back());
  }
  return r;
}

void write_vtu(const TetMesh& m, const Measured& q, const std::string& tets_vtu,
               const std::string& faces_vtu) {
  vtkSmartPointer<vtkPoints> points = make_points(m);
  {
    vtkNew<vtkUnstructuredGrid> ug;
    ug->SetPoints(points);
    ug->Allocate(static_cast<vtkIdType>(m.tets.size()));
    for (const auto& t : m.tets) {
      const vtkIdType ids[4] = {t[0], t[1], t[2], t[3]};
      ug->InsertNextCell(VTK_TETRA, 4, ids);
    }
    const std::size_t n = m.tets.size();
    add_array<vtkIntArray>(ug, "region", n, [&](std::size_t c) { return m.regions[c]; });
    add_array<vtkDoubleArray>(ug, "min_dihedral_deg", n,
                              [&](std::size_t c) { return q.per_tet[c].min_dihedral_deg; });
    add_array<vtkDoubleArray>(ug, "max_dihedral_deg", n,
                              [&](std::size_t c) { return q.per_tet[c].max_dihedral_deg; });
    add_array<vtkDoubleArray>(ug, "radius_edge_ratio", n,
                              [&](std::size_t c) { return q.per_tet[c].rho; });
    add_array<vtkDoubleArray>(ug, "sigma", n, [&](std::size_t c) { return q.per_tet[c].sigma; });
    write(ug, tets_vtu);
  }
  {
    vtkNew<vtkUnstructuredGrid> ug;
    ug->SetPoints(points);
    ug->Allocate(static_cast<vtkIdType>(m.faces.size()));
    for (const auto& f : m.faces) {
      const vtkIdType ids[3] = {f[0], f[1], f[2]};
      ug->InsertNextCell(VTK_TRIANGLE, 3, ids);
    }
    add_array<vtkIntArray>(ug, "marker", m.faces.size(),
                           [&](std::size_t c) { return m.markers[c]; });
    write(ug, faces_vtu);
  }
}

std::vector<std::string> check_vtu(const TetMesh& m, const Measured& q,
                                   const std::string& tets_vtu, const std::string& faces_vtu) {
  std::vector<std::string> problems;
  auto problem = [&](const std::string& file, const std::string& what) {
    problems.push_back(file + ": " + what);
  };
  auto check_array = [&](vtkUnstructuredGrid* ug, const std::string& file, const char* name,
                         const std::vector<int32_t>* expected) {
    vtkDataArray* a = ug->GetCellData()->GetArray(name);
    if (a == nullptr) return problem(file, std::string("no cell data array ") + name);
    if (a->GetNumberOfComponents() != 1 || a->GetNumberOfTuples() != ug->GetNumberOfCells())
      return problem(file, std::string(name) + " has " + std::to_string(a->GetNumberOfTuples()) +
                               " tuples of " + std::to_string(a->GetNumberOfComponents()) +
                               " components, expected one per cell");
    if (expected)
      for (vtkIdType c = 0; c < a->GetNumberOfTuples(); ++c)
        if (a->GetTuple1(c) != (*expected)[c])
          return problem(file, std::string(name) + " of cell " + std::to_string(c) + " differs");
  };

  vtkNew<vtkXMLUnstructuredGridReader> tets_reader;
  if (vtkUnstructuredGrid* ug = read(tets_reader, tets_vtu)) {
    if (ug->GetNumberOfPoints() != static_cast<vtkIdType>(m.points.size()))
      problem(tets_vtu, std::to_string(ug->GetNumberOfPoints()) + " points, expected " +
                            std::to_string(m.points.size()));
    if (ug->GetNumberOfCells() != static_cast<vtkIdType>(m.tets.size())) {
      problem(tets_vtu, std::to_string(ug->GetNumberOfCells()) + " cells, expected " +
                            std::to_string(m.tets.size()));
    } else {
      // Re-measure from what VTK read: the same figures as from memory (binary doubles).
      tq::MeshQuality again;
      vtkNew<vtkIdList> ids;
      bool all_tets = true;
      for (vtkIdType c = 0; c < ug->GetNumberOfCells() && all_tets; ++c) {
        if (ug->GetCellType(c) != VTK_TETRA) {
          all_tets = false;
          problem(tets_vtu, "cell " + std::to_string(c) + " is not a VTK_TETRA");
          break;
        }
        ug->GetCellPoints(c, ids);
        tq::Vec p[4];
        for (int i = 0; i < 4; ++i) ug->GetPoint(ids->GetId(i), p[i].data());
        again.add(tq::tet_quality(p[0], p[1], p[2], p[3]));
      }
      if (all_tets && (again.min_dihedral_deg != q.total.min_dihedral_deg ||
                       again.n_inverted != q.total.n_inverted))
        problem(tets_vtu, "the mesh read back measures differently (min dihedral " +
                              std::to_string(again.min_dihedral_deg) + ")");
      check_array(ug, tets_vtu, "region", &m.regions);
      for (const char* name : {"min_dihedral_deg", "max_dihedral_deg", "radius_edge_ratio", "sigma"})
        check_array(ug, tets_vtu, name, nullptr);
    }
  } else {
    problem(tets_vtu, "cannot be read");
  }

  vtkNew<vtkXMLUnstructuredGridReader> faces_reader;
  if (vtkUnstructuredGrid* ug = read(faces_reader, faces_vtu)) {
    if (ug->GetNumberOfCells() != static_cast<vtkIdType>(m.faces.size())) {
      problem(faces_vtu, std::to_string(ug->GetNumberOfCells()) + " cells, expected " +
                             std::to_string(m.faces.size()));
    } else {
      for (vtkIdType c = 0; c < ug->GetNumberOfCells(); ++c)
        if (ug->GetCellType(c) != VTK_TRIANGLE) {
          problem(faces_vtu, "cell " + std::to_string(c) + " is not a VTK_TRIANGLE");
          break;
        }
      check_array(ug, faces_vtu, "marker", &m.markers);
    }
  } else {
    problem(faces_vtu, "cannot be read");
  }
  return problems;
}

}  // namespace harness
