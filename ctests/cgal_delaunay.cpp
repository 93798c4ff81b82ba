// cgal_delaunay: the CGAL reference for slivermesh's Delaunay kernel.
//
// Reads a point file in slivermesh's format (one "x y z" per line, '#' comments, blank lines
// ignored), builds CGAL's Delaunay_triangulation_3 with the Epick kernel by range insertion
// (T.insert(begin, end), which spatially sorts first), times only that call, and prints one JSON
// object on stdout:
//   n_points, n_vertices, n_tets (finite cells), seconds, peak_rss_mb (10^6 bytes, VmHWM right
//   after the triangulation), bytes_per_tet (peak RSS bytes / n_tets)
// With --checksum it also builds a second, untimed triangulation whose vertices carry their input
// index and adds "tets_checksum": the same order-independent checksum of the set of finite tets
// (as sorted input-index quadruples) that `slivermesh delaunay --stats-json` reports, so the two
// triangulations can be compared tet by tet.
//
// Usage: cgal_delaunay POINTS [--checksum]

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Delaunay = CGAL::Delaunay_triangulation_3<K>;

using Vb = CGAL::Triangulation_vertex_base_with_info_3<std::uint32_t, K>;
using Tds = CGAL::Triangulation_data_structure_3<Vb>;
using DelaunayInfo = CGAL::Delaunay_triangulation_3<K, Tds>;

namespace {

// Peak resident set size in bytes (VmHWM), or -1 when unavailable.
long long peak_rss_bytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) {
      return std::atoll(line.c_str() + 6) * 1024LL;
    }
  }
  return -1;
}

[[noreturn]] void fail(const std::string& path, long line, const std::string& msg) {
  std::cerr << "error: " << path;
  if (line > 0) std::cerr << ":" << line;
  std::cerr << ": " << msg << "\n";
  std::exit(1);
}

std::vector<Point> read_points(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, 0, std::string("cannot open: ") + std::strerror(errno));
  std::vector<Point> pts;
  std::string line;
  long line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    const char* s = line.c_str();
    double xyz[3];
    int count = 0;
    for (;;) {
      while (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n' || *s == '\f' || *s == '\v') ++s;
      if (*s == '\0') break;
      const char* tok = s;
      while (*s != '\0' && !std::isspace(static_cast<unsigned char>(*s))) ++s;
      std::string t(tok, s);
      if (count < 3) {
        char* end = nullptr;
        errno = 0;
        double v = std::strtod(t.c_str(), &end);
        if (end == t.c_str() || *end != '\0') fail(path, line_no, "`" + t + "` is not a number");
        if (!std::isfinite(v)) fail(path, line_no, "`" + t + "` is not finite");
        xyz[count] = v;
      }
      ++count;
    }
    if (count == 0) continue;
    if (count != 3) {
      fail(path, line_no, "expected 3 numbers (x y z), found " + std::to_string(count));
    }
    pts.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  return pts;
}

std::uint64_t mix(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Same definition as slivermesh's tets_checksum (src/cli/tri.rs).
std::uint64_t tet_hash(std::uint32_t t[4]) {
  std::sort(t, t + 4);
  std::uint64_t h = mix(t[0]);
  for (int i = 1; i < 4; ++i) h = mix(h ^ t[i]);
  return h;
}

std::uint64_t checksum(const std::vector<Point>& pts) {
  std::vector<std::pair<Point, std::uint32_t>> indexed;
  indexed.reserve(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    indexed.emplace_back(pts[i], static_cast<std::uint32_t>(i));
  }
  DelaunayInfo T(indexed.begin(), indexed.end());
  std::uint64_t sum = 0;
  for (auto c = T.finite_cells_begin(); c != T.finite_cells_end(); ++c) {
    std::uint32_t t[4];
    for (int i = 0; i < 4; ++i) t[i] = c->vertex(i)->info();
    sum += tet_hash(t);
  }
  return sum;
}

}  // namespace

int main(int argc, char** argv) {
  std::string path;
  bool want_checksum = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--checksum") {
      want_checksum = true;
    } else if (a == "-h" || a == "--help") {
      std::cout << "usage: cgal_delaunay POINTS [--checksum]\n";
      return 0;
    } else if (path.empty() && !a.empty() && a[0] != '-') {
      path = a;
    } else {
      std::cerr << "error: unexpected argument `" << a << "`\nusage: cgal_delaunay POINTS [--checksum]\n";
      return 1;
    }
  }
  if (path.empty()) {
    std::cerr << "usage: cgal_delaunay POINTS [--checksum]\n";
    return 1;
  }
  std::vector<Point> pts = read_points(path);
  if (pts.empty()) fail(path, 0, "no points");

  Delaunay T;
  auto t0 = std::chrono::steady_clock::now();
  T.insert(pts.begin(), pts.end());
  auto t1 = std::chrono::steady_clock::now();
  double seconds = std::chrono::duration<double>(t1 - t0).count();
  long long peak = peak_rss_bytes();

  std::size_t n_tets = T.number_of_finite_cells();
  std::size_t n_vertices = T.number_of_vertices();

  std::printf("{\n");
  std::printf("  \"n_points\": %zu,\n", pts.size());
  std::printf("  \"n_vertices\": %zu,\n", n_vertices);
  std::printf("  \"n_tets\": %zu,\n", n_tets);
  std::printf("  \"dimension\": %d,\n", T.dimension());
  std::printf("  \"seconds\": %.6f,\n", seconds);
  std::printf("  \"points_per_second\": %.1f,\n", pts.size() / std::max(seconds, 1e-12));
  if (peak >= 0) {
    std::printf("  \"peak_rss_mb\": %.3f,\n", peak / 1e6);
    std::printf("  \"bytes_per_tet\": %.3f", n_tets > 0 ? double(peak) / double(n_tets) : 0.0);
  } else {
    std::printf("  \"peak_rss_mb\": null,\n  \"bytes_per_tet\": null");
  }
  if (want_checksum) {
    T.clear();
    std::printf(",\n  \"tets_checksum\": \"%016llx\"", static_cast<unsigned long long>(checksum(pts)));
  }
  std::printf("\n}\n");
  return 0;
}
