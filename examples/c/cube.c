/* Meshes the unit cube with a spacing given by a C callback (fine at the origin corner, coarse
 * at the opposite one), writes it as .vtu with per-tet quality, and prints the quality report.
 *
 *     ./cube_c [output.vtu]
 *
 * Build against an installed slivermesh (scripts/install.sh PREFIX):
 *     cmake -S examples/c -B build/example-c -DCMAKE_PREFIX_PATH=PREFIX
 *     cmake --build build/example-c
 * or with pkg-config:
 *     cc cube.c $(pkg-config --cflags --libs slivermesh) -Wl,-rpath,PREFIX/lib -o cube_c */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <slivermesh.h>

/* The spacing callback's user data. */
struct grading {
    double h_min; /* at the origin */
    double h_max; /* at (1, 1, 1) */
};

static double spacing(double x, double y, double z, void *user_data) {
    const struct grading *g = (const struct grading *)user_data;
    double t = sqrt(x * x + y * y + z * z) / sqrt(3.0);
    return g->h_min + (g->h_max - g->h_min) * t;
}

/* Prints a line each time the vertex count doubles (the fraction is only an estimate: the share
 * of the "max_vertices" budget used); returning non-zero would cancel sm_refine. */
static int32_t progress(double fraction, size_t n_vertices, void *user_data) {
    size_t *next = (size_t *)user_data;
    if (n_vertices >= *next) {
        printf("  %zu vertices (%.4f %% of the vertex budget)\n", n_vertices, 100.0 * fraction);
        *next = 2 * n_vertices;
    }
    return 0;
}

/* Prints the failing call and the library's message, then exits. */
static void check(sm_mesher *m, sm_status s, const char *what) {
    if (s != SM_OK) {
        fprintf(stderr, "%s failed: %s: %s\n", what, sm_status_str(s), sm_last_error(m));
        sm_destroy(m);
        exit(1);
    }
}

int main(int argc, char **argv) {
    static const double xyz[8 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,
                                      0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
    /* Vertex ids are 0-based; each facet is a planar polygon, with a boundary marker. */
    static const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                         {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    const char *out = argc > 1 ? argv[1] : "cube_c.vtu";
    struct grading g = {0.08, 0.3};
    size_t next_report = 0;
    sm_quality q;
    const char *reason;
    int k;

    sm_mesher *m = sm_create();
    if (m == NULL) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }
    printf("slivermesh %s\n", sm_version());
    check(m, sm_add_vertices(m, xyz, 8), "sm_add_vertices");
    for (k = 0; k < 6; k++) {
        check(m, sm_add_facet(m, faces[k], 4, k + 1), "sm_add_facet");
    }
    check(m, sm_set_spacing_cb(m, spacing, &g), "sm_set_spacing_cb");
    check(m, sm_set_progress_cb(m, progress, &next_report), "sm_set_progress_cb");
    check(m, sm_set_param(m, "rho0", 2.0), "sm_set_param");
    check(m, sm_set_param(m, "seed", 1), "sm_set_param");
    check(m, sm_refine(m), "sm_refine");
    check(m, sm_write(m, out), "sm_write");
    check(m, sm_get_quality(m, &q), "sm_get_quality");

    printf("wrote %s\n", out);
    printf("vertices %zu, tets %zu, boundary triangles %zu\n", q.n_vertices, q.n_tets,
           q.n_boundary_faces);
    printf("max radius-edge %.3f, min sigma %.4f, dihedral angles [%.2f, %.2f] deg\n", q.max_rho,
           q.min_sigma, q.min_dihedral_deg, q.max_dihedral_deg);
    printf("tets with a dihedral below 5/10/15/20 deg: %zu/%zu/%zu/%zu\n", q.tets_below_deg[0],
           q.tets_below_deg[1], q.tets_below_deg[2], q.tets_below_deg[3]);
    printf("max R/f %.3f, edge/f in [%.3f, %.3f] (median %.3f)\n", q.max_size_ratio,
           q.edge_ratio_min, q.edge_ratio_max, q.edge_ratio_median);
    reason = sm_stop_reason(m);
    printf("complete: %s%s%s, %.3f s\n", q.complete ? "yes" : "no", reason ? ": " : "",
           reason ? reason : "", q.seconds_total);
    sm_destroy(m);
    return 0;
}
