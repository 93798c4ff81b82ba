// Meshes the unit cube through the C ABI from C++: a small RAII wrapper turning statuses into
// exceptions, a spacing given as a lambda (through a trampoline: no exception may cross the C
// boundary, so one becomes NaN, which fails sm_refine with SM_ERR_SPACING), results copied into
// std::vector, the mesh written as .vtu, and the quality printed.
//
//     ./cube_cpp [output.vtu]
//
// Build against an installed slivermesh (scripts/install.sh PREFIX):
//     cmake -S examples/cpp -B build/example-cpp -DCMAKE_PREFIX_PATH=PREFIX
//     cmake --build build/example-cpp
#include <slivermesh.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

// Owns an sm_mesher; every failing call throws with the library's message.
class Mesher {
public:
    using SpacingFn = std::function<double(double, double, double)>;

    Mesher() : m_(sm_create(), &sm_destroy) {
        if (!m_) throw std::bad_alloc();
    }

    void add_vertices(const std::vector<std::array<double, 3>> &points) {
        check(sm_add_vertices(m_.get(), points.front().data(), points.size()), "sm_add_vertices");
    }
    void add_facet(const std::vector<uint32_t> &ids, int32_t marker) {
        check(sm_add_facet(m_.get(), ids.data(), ids.size(), marker), "sm_add_facet");
    }
    void set_param(const char *name, double value) {
        check(sm_set_param(m_.get(), name, value), "sm_set_param");
    }
    // The function must outlive refine(); it is stored in this object.
    void set_spacing(SpacingFn f) {
        spacing_ = std::move(f);
        check(sm_set_spacing_cb(m_.get(), &Mesher::trampoline, &spacing_), "sm_set_spacing_cb");
    }
    void refine() { check(sm_refine(m_.get()), "sm_refine"); }
    void write(const std::string &path) const {
        check(sm_write(m_.get(), path.c_str()), "sm_write");
    }

    std::vector<double> vertices() const {
        std::vector<double> xyz(3 * sm_num_vertices(m_.get()));
        check(sm_get_vertices(m_.get(), xyz.data(), xyz.size() / 3), "sm_get_vertices");
        return xyz;
    }
    std::vector<uint32_t> tets() const {
        std::vector<uint32_t> t(4 * sm_num_tets(m_.get()));
        check(sm_get_tets(m_.get(), t.data(), nullptr, t.size() / 4), "sm_get_tets");
        return t;
    }
    sm_quality quality() const {
        sm_quality q{};
        check(sm_get_quality(m_.get(), &q), "sm_get_quality");
        return q;
    }

private:
    static double trampoline(double x, double y, double z, void *user_data) noexcept {
        try {
            return (*static_cast<SpacingFn *>(user_data))(x, y, z);
        } catch (...) {
            return std::numeric_limits<double>::quiet_NaN();
        }
    }

    void check(sm_status s, const char *what) const {
        if (s != SM_OK) {
            throw std::runtime_error(std::string(what) + " failed: " + sm_status_str(s) + ": " +
                                     sm_last_error(m_.get()));
        }
    }

    std::unique_ptr<sm_mesher, decltype(&sm_destroy)> m_;
    SpacingFn spacing_;
};

}  // namespace

int main(int argc, char **argv) {
    const std::string out = argc > 1 ? argv[1] : "cube_cpp.vtu";
    try {
        Mesher m;
        std::vector<std::array<double, 3>> corners;
        for (int i = 0; i < 8; ++i) {
            corners.push_back({double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)});
        }
        m.add_vertices(corners);
        const std::vector<std::vector<uint32_t>> faces = {{0, 2, 3, 1}, {4, 5, 7, 6},
                                                          {0, 1, 5, 4}, {2, 6, 7, 3},
                                                          {0, 4, 6, 2}, {1, 3, 7, 5}};
        for (size_t k = 0; k < faces.size(); ++k) m.add_facet(faces[k], int32_t(k + 1));

        // Fine near the plane z = 0.5, coarse away from it.
        const double h_fine = 0.06, h_coarse = 0.25;
        m.set_spacing([=](double, double, double z) {
            return h_fine + (h_coarse - h_fine) * std::abs(2.0 * z - 1.0);
        });
        m.set_param("rho0", 2.0);
        m.refine();
        m.write(out);

        const sm_quality q = m.quality();
        const auto xyz = m.vertices();
        const auto tets = m.tets();
        double volume = 0;
        for (size_t t = 0; t < tets.size(); t += 4) {
            const double *a = &xyz[3 * tets[t]], *b = &xyz[3 * tets[t + 1]],
                         *c = &xyz[3 * tets[t + 2]], *d = &xyz[3 * tets[t + 3]];
            const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
            volume += (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                       u[2] * (v[0] * w[1] - v[1] * w[0])) /
                      6.0;
        }
        std::printf("slivermesh %s: wrote %s\n", sm_version(), out.c_str());
        std::printf("vertices %zu, tets %zu, boundary triangles %zu, volume %.12f\n",
                    q.n_vertices, q.n_tets, q.n_boundary_faces, volume);
        std::printf("max radius-edge %.3f, min sigma %.4f, dihedral angles [%.2f, %.2f] deg\n",
                    q.max_rho, q.min_sigma, q.min_dihedral_deg, q.max_dihedral_deg);
        std::printf("complete: %s, %.3f s\n", q.complete ? "yes" : "no", q.seconds_total);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
