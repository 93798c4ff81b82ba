// Merging edge-adjacent, exactly coplanar facets of a triangulated surface into polygon facets:
// the algorithm of the library's plc::coplanar (`slivermesh mesh` applies it to every .off by
// default), so the harness gives the C ABI the same PLC the CLI meshes. Coplanarity and
// collinearity are CGAL's exact predicates (Epick filters, then exact arithmetic).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <optional>
#include <set>

#include "domain.hpp"

namespace harness {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using P3 = K::Point_3;

P3 pt(const Vec3& v) { return {v[0], v[1], v[2]}; }

struct Plane {
  P3 a, b, c;
  Vec3 normal;  // Newell's, floating point: only its direction's sign is compared
  bool contains(const Vec3& q) const { return CGAL::orientation(a, b, c, pt(q)) == CGAL::COPLANAR; }
};

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// The plane of a mergeable facet: one polygon without holes, no repeated neighbours, planar,
// not all collinear.
std::optional<Plane> plane_of(const Facet& f, const std::vector<Vec3>& v) {
  const Polygon& p = f.outer;
  if (!f.holes.empty() || p.size() < 3) return std::nullopt;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p[i] == p[(i + 1) % p.size()]) return std::nullopt;
  const P3 a = pt(v[p[0]]);
  std::optional<P3> b, c;
  for (uint32_t id : p)
    if (pt(v[id]) != a) { b = pt(v[id]); break; }
  if (!b) return std::nullopt;
  for (uint32_t id : p)
    if (!CGAL::collinear(a, *b, pt(v[id]))) { c = pt(v[id]); break; }
  if (!c) return std::nullopt;
  Plane pl{a, *b, *c, newell(v, p)};
  if (pl.normal == Vec3{0, 0, 0}) return std::nullopt;
  for (uint32_t id : p)
    if (!pl.contains(v[id])) return std::nullopt;
  return pl;
}

struct UnionFind {
  std::vector<std::size_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::size_t find(std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::size_t a, std::size_t b) {  // the smaller index stays the root
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// The merged facet of a group, or nothing when its boundary is not simple loops with exactly
// one outer loop, or a vertex of the group lies on no boundary loop.
std::optional<Facet> merge_group(const std::vector<std::size_t>& group,
                                 const std::vector<Facet>& facets, const std::vector<Vec3>& v,
                                 const Vec3& normal) {
  std::vector<std::pair<uint32_t, uint32_t>> directed;
  for (std::size_t fi : group) {
    const Polygon& p = facets[fi].outer;
    for (std::size_t i = 0; i < p.size(); ++i) directed.push_back({p[i], p[(i + 1) % p.size()]});
  }
  std::map<std::pair<uint32_t, uint32_t>, long> count;
  for (auto [a, b] : directed) {
    auto rev = count.find({b, a});
    if (rev != count.end() && rev->second > 0) --rev->second;
    else ++count[{a, b}];
  }
  std::vector<std::pair<uint32_t, uint32_t>> boundary;
  for (auto e : directed) {
    auto it = count.find(e);
    if (it != count.end() && it->second > 0) {
      --it->second;
      boundary.push_back(e);
    }
  }
  std::map<uint32_t, uint32_t> next;
  for (auto [a, b] : boundary)
    if (!next.emplace(a, b).second) return std::nullopt;  // patches touching at a vertex
  std::set<uint32_t> used;
  std::optional<Polygon> outer;
  std::vector<Polygon> holes;
  for (auto [start, unused] : boundary) {
    (void)unused;
    if (used.count(start)) continue;
    Polygon loop{start};
    used.insert(start);
    auto it = next.find(start);
    if (it == next.end()) return std::nullopt;
    for (uint32_t cur = it->second; cur != start;) {
      if (!used.insert(cur).second || loop.size() > boundary.size()) return std::nullopt;
      loop.push_back(cur);
      auto n = next.find(cur);
      if (n == next.end()) return std::nullopt;
      cur = n->second;
    }
    if (loop.size() < 3) return std::nullopt;
    if (dot(newell(v, loop), normal) > 0.0) {
      if (outer) return std::nullopt;
      outer = std::move(loop);
    } else {
      holes.push_back(std::move(loop));
    }
  }
  for (std::size_t fi : group)
    for (uint32_t id : facets[fi].outer)
      if (!used.count(id)) return std::nullopt;  // an interior vertex would be lost
  if (!outer) return std::nullopt;
  return Facet{*outer, holes, 0};
}

}  // namespace

void merge_coplanar_facets(Domain& d) {
  const std::vector<Vec3>& v = d.vertices;
  std::vector<Facet> facets = std::move(d.facets);
  std::vector<std::optional<Plane>> planes;
  for (const Facet& f : facets) planes.push_back(plane_of(f, v));

  // Undirected edge -> (facet, forward) uses, visited in sorted edge order (deterministic).
  std::map<std::pair<uint32_t, uint32_t>, std::vector<std::pair<std::size_t, bool>>> edges;
  for (std::size_t fi = 0; fi < facets.size(); ++fi) {
    if (!planes[fi]) continue;
    const Polygon& p = facets[fi].outer;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const uint32_t a = p[i], b = p[(i + 1) % p.size()];
      edges[{std::min(a, b), std::max(a, b)}].push_back({fi, a < b});
    }
  }
  UnionFind uf(facets.size());
  for (const auto& [key, uses] : edges) {
    (void)key;
    if (uses.size() != 2) continue;
    const auto [f, df] = uses[0];
    const auto [g, dg] = uses[1];
    if (f == g || df == dg || uf.find(f) == uf.find(g)) continue;
    if (dot(planes[f]->normal, planes[g]->normal) <= 0.0) continue;
    const Polygon& pg = facets[g].outer;
    if (std::all_of(pg.begin(), pg.end(), [&](uint32_t id) { return planes[f]->contains(v[id]); }))
      uf.unite(f, g);
  }
  std::map<std::size_t, std::size_t> group_of_root;
  std::vector<std::vector<std::size_t>> groups;
  for (std::size_t fi = 0; fi < facets.size(); ++fi) {
    auto [it, fresh] = group_of_root.emplace(uf.find(fi), groups.size());
    if (fresh) groups.emplace_back();
    groups[it->second].push_back(fi);
  }
  d.facets.clear();
  for (const auto& g : groups) {
    if (g.size() > 1 && planes[g[0]]) {
      if (auto merged = merge_group(g, facets, v, planes[g[0]]->normal)) {
        d.facets.push_back(std::move(*merged));
        continue;
      }
    }
    for (std::size_t fi : g) d.facets.push_back(facets[fi]);
  }
  for (std::size_t i = 0; i < d.facets.size(); ++i) d.facets[i].marker = static_cast<int32_t>(i + 1);
}

}  // namespace harness
