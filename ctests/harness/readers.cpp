// .off and TetGen .poly readers for the harness: line-based records, '#' comments, errors naming
// the file and line. The harness reads its inputs itself so the C ABI is fed exactly what a
// C/C++ user would pass (no reader inside the library is involved).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "domain.hpp"

namespace harness {
namespace {

// The non-empty records of a text file (comments stripped), each with its line number.
class Records {
 public:
  explicit Records(const std::string& path) : path_(path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::string line;
    std::size_t no = 0;
    while (std::getline(in, line)) {
      ++no;
      line = line.substr(0, line.find('#'));
      std::istringstream words(line);
      std::vector<std::string> w;
      for (std::string s; words >> s;) w.push_back(s);
      if (!w.empty()) lines_.push_back({no, std::move(w)});
    }
  }

  bool done() const { return next_ >= lines_.size(); }
  // The next record's words; the error names the section that was expected.
  const std::vector<std::string>& next(const std::string& what) {
    if (done()) fail_at(lines_.empty() ? 0 : lines_.back().first, "file ends; expected " + what);
    current_ = lines_[next_].first;
    return lines_[next_++].second;
  }
  [[noreturn]] void fail(const std::string& msg) const { fail_at(current_, msg); }
  [[noreturn]] void fail_at(std::size_t line, const std::string& msg) const {
    throw std::runtime_error(path_ + ":" + std::to_string(line) + ": " + msg);
  }

  double number(const std::string& w) const {
    char* end = nullptr;
    const double v = std::strtod(w.c_str(), &end);
    if (end == w.c_str() || *end != '\0' || !std::isfinite(v))
      fail("'" + w + "' is not a finite number");
    return v;
  }
  long integer(const std::string& w) const {
    char* end = nullptr;
    const long v = std::strtol(w.c_str(), &end, 10);
    if (end == w.c_str() || *end != '\0') fail("'" + w + "' is not an integer");
    return v;
  }
  std::size_t count(const std::string& w, const std::string& what) const {
    const long v = integer(w);
    if (v < 0) fail(what + " " + w + " is negative");
    return static_cast<std::size_t>(v);
  }
  void need(const std::vector<std::string>& w, std::size_t n, const std::string& what) const {
    if (w.size() < n)
      fail(what + ": expected " + std::to_string(n) + " fields, found " + std::to_string(w.size()));
  }

 private:
  std::string path_;
  std::vector<std::pair<std::size_t, std::vector<std::string>>> lines_;
  std::size_t next_ = 0;
  std::size_t current_ = 0;
};

bool ends_with(const std::string& s, const std::string& tail) {
  if (s.size() < tail.size()) return false;
  return std::equal(tail.rbegin(), tail.rend(), s.rbegin(),
                    [](char a, char b) { return std::tolower(a) == std::tolower(b); });
}


// Whether q lies inside polygon p, in the coordinate plane the polygon's normal is closest to.
// Floating point: it only decides which polygon a facet hole point marks as a hole.
bool inside_polygon(const std::vector<Vec3>& v, const Polygon& p, const Vec3& q) {
  const Vec3 n = newell(v, p);
  int drop = 0;
  for (int k = 1; k < 3; ++k)
    if (std::fabs(n[k]) > std::fabs(n[drop])) drop = k;
  const int u = (drop + 1) % 3, w = (drop + 2) % 3;
  bool in = false;
  for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
    const Vec3& a = v[p[i]];
    const Vec3& b = v[p[j]];
    if ((a[w] > q[w]) != (b[w] > q[w]) &&
        q[u] < (b[u] - a[u]) * (q[w] - a[w]) / (b[w] - a[w]) + a[u])
      in = !in;
  }
  return in;
}

}  // namespace

double enclosed_volume(const std::vector<Vec3>& v, const std::vector<Polygon>& polygons) {
  double six_v = 0.0;
  for (const Polygon& p : polygons) {
    const Vec3& a = v[p[0]];
    for (std::size_t i = 1; i + 1 < p.size(); ++i) {
      const Vec3& b = v[p[i]];
      const Vec3& c = v[p[i + 1]];
      six_v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
               a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
  }
  return six_v / 6.0;
}

// OFF: "OFF", then "nv nf ne" (on the same line or the next), nv lines "x y z", nf lines
// "k v1 ... vk [colour]". Facet i gets marker i + 1.
Domain read_off(const std::string& path) {
  Records r(path);
  std::vector<std::string> head = r.next("the OFF header");
  if (head[0] != "OFF") r.fail("expected the OFF header, found '" + head[0] + "'");
  head.erase(head.begin());
  if (head.empty()) head = r.next("the counts 'nv nf ne'");
  r.need(head, 2, "counts 'nv nf ne'");
  const std::size_t nv = r.count(head[0], "vertex count");
  const std::size_t nf = r.count(head[1], "face count");
  Domain d;
  d.path = path;
  for (std::size_t i = 0; i < nv; ++i) {
    const auto& w = r.next("vertex " + std::to_string(i));
    r.need(w, 3, "vertex " + std::to_string(i));
    d.vertices.push_back({r.number(w[0]), r.number(w[1]), r.number(w[2])});
  }
  for (std::size_t i = 0; i < nf; ++i) {
    const auto& w = r.next("face " + std::to_string(i));
    const std::size_t k = r.count(w[0], "corner count");
    if (k < 3) r.fail("face " + std::to_string(i) + " has " + std::to_string(k) + " corners");
    r.need(w, k + 1, "face " + std::to_string(i));
    Polygon p;
    for (std::size_t j = 1; j <= k; ++j) {
      const std::size_t id = r.count(w[j], "vertex id");
      if (id >= nv)
        r.fail("face " + std::to_string(i) + ": vertex id " + w[j] + " >= " + std::to_string(nv));
      p.push_back(static_cast<uint32_t>(id));
    }
    d.facets.push_back({p, {}, static_cast<int32_t>(i + 1)});
    d.surface.push_back(std::move(p));
  }
  d.volume = std::fabs(enclosed_volume(d.vertices, d.surface));
  return d;
}

// TetGen .poly (3D): nodes "<n> 3 [#attr] [#markers]" + "<id> x y z ...", facets
// "<n> [markers]" + per facet "<#polygons> [#holes] [marker]", its polygons "<k> v1 .. vk"
// (continuing on following lines if needed) and hole points "<id> x y z"; volume holes
// "<n>" + "<id> x y z"; optional regions "<n>" + "<id> x y z attribute [max volume]".
// A facet polygon holding one of the facet's hole points becomes a hole polygon; exactly one
// polygon must remain, the outer one (the C ABI has no constraint segments inside facets).
Domain read_poly(const std::string& path) {
  Records r(path);
  Domain d;
  d.path = path;
  {
    const auto& w = r.next("the node header");
    const std::size_t n = r.count(w[0], "node count");
    if (n == 0) r.fail("nodes in a separate .node file are not supported by the harness");
    if (w.size() > 1 && w[1] != "3") r.fail("dimension " + w[1] + ": only 3D files are read");
    long base = -1;
    for (std::size_t i = 0; i < n; ++i) {
      const auto& v = r.next("node " + std::to_string(i));
      r.need(v, 4, "node");
      const long id = r.integer(v[0]);
      if (base < 0) {
        if (id != 0 && id != 1) r.fail("the first node id must be 0 or 1, found " + v[0]);
        base = id;
      }
      if (id != base + static_cast<long>(i))
        r.fail("node ids must be consecutive: expected " + std::to_string(base + long(i)));
      d.vertices.push_back({r.number(v[1]), r.number(v[2]), r.number(v[3])});
    }
    auto vertex_id = [&](const std::string& s) {
      const long id = r.integer(s) - base;
      if (id < 0 || id >= static_cast<long>(n)) r.fail("vertex id " + s + " out of range");
      return static_cast<uint32_t>(id);
    };

    const auto& fh = r.next("the facet header");
    const std::size_t nf = r.count(fh[0], "facet count");
    const bool markers = fh.size() > 1 && r.integer(fh[1]) != 0;
    bool has_holes = false;
    for (std::size_t f = 0; f < nf; ++f) {
      const std::string name = "facet " + std::to_string(f);
      const auto& h = r.next(name);
      const std::size_t np = r.count(h[0], "polygon count");
      const std::size_t nh = h.size() > 1 ? r.count(h[1], "hole count") : 0;
      const int32_t marker = markers && h.size() > 2 ? static_cast<int32_t>(r.integer(h[2])) : 1;
      std::vector<Polygon> polygons;
      for (std::size_t p = 0; p < np; ++p) {
        std::vector<std::string> w = r.next(name + " polygon " + std::to_string(p));
        const std::size_t k = r.count(w[0], "corner count");
        while (w.size() < k + 1) {  // TetGen lets a corner list continue on the next lines
          const auto& more = r.next(name + " polygon corners");
          w.insert(w.end(), more.begin(), more.end());
        }
        if (k < 3)
          r.fail(name + ": a polygon of " + std::to_string(k) +
                 " corners (a segment or point inside a facet) cannot be passed to the C ABI");
        Polygon poly;
        for (std::size_t j = 1; j <= k; ++j) poly.push_back(vertex_id(w[j]));
        polygons.push_back(std::move(poly));
      }
      std::vector<bool> is_hole(polygons.size(), false);
      for (std::size_t k = 0; k < nh; ++k) {
        const auto& w = r.next(name + " hole point");
        r.need(w, 4, name + " hole point");
        const Vec3 q{r.number(w[1]), r.number(w[2]), r.number(w[3])};
        bool found = false;
        for (std::size_t p = 0; p < polygons.size() && !found; ++p) {
          // The innermost polygon holding q: one that holds q and no other polygon that does.
          if (!inside_polygon(d.vertices, polygons[p], q)) continue;
          bool innermost = true;
          for (std::size_t o = 0; o < polygons.size(); ++o)
            if (o != p && inside_polygon(d.vertices, polygons[o], q) &&
                inside_polygon(d.vertices, polygons[p], d.vertices[polygons[o][0]]))
              innermost = false;
          if (innermost) is_hole[p] = found = true;
        }
        if (!found) r.fail(name + ": hole point " + w[0] + " lies in none of its polygons");
      }
      Facet facet;
      facet.marker = marker;
      for (std::size_t p = 0; p < polygons.size(); ++p) {
        if (is_hole[p]) {
          facet.holes.push_back(polygons[p]);
        } else if (facet.outer.empty()) {
          facet.outer = polygons[p];
        } else {
          r.fail(name + ": polygons " + std::to_string(p) +
                 " and an earlier one are both outer boundaries (not a hole); the C ABI takes "
                 "one outer polygon per facet");
        }
      }
      if (facet.outer.empty()) r.fail(name + ": no outer polygon");
      has_holes = has_holes || !facet.holes.empty();
      if (facet.holes.empty()) d.surface.push_back(facet.outer);
      d.facets.push_back(std::move(facet));
    }
    if (has_holes) d.cgal_unsupported = "facets with holes";
  }
  {
    const auto& w = r.next("the volume hole count");
    const std::size_t n = r.count(w[0], "hole count");
    for (std::size_t i = 0; i < n; ++i) {
      const auto& h = r.next("volume hole " + std::to_string(i));
      r.need(h, 4, "volume hole");
      d.holes.push_back({r.number(h[1]), r.number(h[2]), r.number(h[3])});
    }
    if (n > 0) d.cgal_unsupported = "volume holes";
  }
  if (!r.done()) {
    const auto& w = r.next("the region count");
    const std::size_t n = r.count(w[0], "region count");
    for (std::size_t i = 0; i < n; ++i) {
      const auto& g = r.next("region " + std::to_string(i));
      r.need(g, 5, "region");
      const double attr = r.number(g[4]);
      if (attr != std::floor(attr) || std::fabs(attr) > 2e9)
        r.fail("region attribute " + g[4] + " is not an integer");
      // TetGen's maximum volume -> the edge of the regular tet of that volume (as the library's
      // own .poly reader does).
      const double v = g.size() > 5 ? r.number(g[5]) : -1.0;
      const double size = v > 0.0 ? std::cbrt(v * 6.0 * std::sqrt(2.0)) : 0.0;
      d.regions.push_back({{r.number(g[1]), r.number(g[2]), r.number(g[3])},
                           static_cast<int32_t>(attr), size});
    }
    if (n > 1) d.cgal_unsupported = "several regions";
  }
  if (!r.done()) {
    r.next("nothing");
    r.fail("unexpected data after the regions");
  }
  if (!d.cgal_unsupported.empty()) d.surface.clear();
  return d;
}

Domain read_domain(const std::string& path, bool merge_coplanar) {
  if (ends_with(path, ".off")) {
    Domain d = read_off(path);
    if (merge_coplanar) merge_coplanar_facets(d);
    return d;
  }
  if (ends_with(path, ".poly")) return read_poly(path);
  throw std::runtime_error(path + ": unknown extension (the harness reads .off and .poly)");
}

}  // namespace harness
