/* The surface mode's parameters through the C ABI: "surface_mode", "feature_angle" and
 * "surface_distance" are set and read back, refused values (surface_mode 2, feature_angle 0 or
 * 200, surface_distance -1, ...) give SM_ERR_INVALID_ARGUMENT with a message naming the
 * parameter and leave the previous value; the default (keep) meshes a closed triangulated cube;
 * and a run in approximate mode on that cube.
 *
 * Compile-time switch: -DSM_TEST_APPROX_RUN=0 leaves the approximate-mode run out. */
#include "common.h"

#ifndef SM_TEST_APPROX_RUN
#define SM_TEST_APPROX_RUN 1
#endif

/* The parameter `name` reads back as `want`. */
#define CHECK_PARAM(m, name, want)                                                            \
    do {                                                                                      \
        double v_ = -12345.0;                                                                 \
        CHECK_STATUS(m, sm_get_param(m, name, &v_), SM_OK);                                   \
        if (v_ != (want)) {                                                                   \
            fprintf(stderr, "%s:%d: %s = %g, want %g\n", __FILE__, __LINE__, name, v_, (want)); \
            g_failures++;                                                                     \
        }                                                                                     \
    } while (0)

/* sm_set_param(name, value) is refused with a message naming `name` and containing `why`;
 * `name` then still reads `old` (a successful call clears the message: checked before). */
#define CHECK_REFUSED(m, name, value, why, old)                                  \
    do {                                                                         \
        CHECK_STATUS(m, sm_set_param(m, name, value), SM_ERR_INVALID_ARGUMENT); \
        CHECK_ERROR_HAS(m, name);                                                \
        CHECK_ERROR_HAS(m, why);                                                 \
        CHECK_PARAM(m, name, old);                                               \
    } while (0)

static void test_surface_params(void) {
    sm_mesher *m = sm_create();
    double v = -1;

    /* Defaults: keep, 40 degrees, 0 (= 0.001 x the bounding-box diagonal). */
    CHECK_PARAM(m, "surface_mode", 0.0);
    CHECK_PARAM(m, "feature_angle", 40.0);
    CHECK_PARAM(m, "surface_distance", 0.0);

    CHECK_STATUS(m, sm_set_param(m, "surface_mode", 1), SM_OK);
    CHECK_PARAM(m, "surface_mode", 1.0);
    CHECK_STATUS(m, sm_set_param(m, "surface_mode", 0), SM_OK);
    CHECK_PARAM(m, "surface_mode", 0.0);
    CHECK_STATUS(m, sm_set_param(m, "surface_mode", 1), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "feature_angle", 30), SM_OK);
    CHECK_PARAM(m, "feature_angle", 30.0);
    CHECK_STATUS(m, sm_set_param(m, "surface_distance", 0.01), SM_OK);
    CHECK_PARAM(m, "surface_distance", 0.01);

    CHECK_REFUSED(m, "surface_mode", 2, "0 (keep", 1.0);
    CHECK_REFUSED(m, "surface_mode", 2, "1 (approximate", 1.0);
    CHECK_REFUSED(m, "surface_mode", -1, "0 (keep", 1.0);
    CHECK_REFUSED(m, "surface_mode", 0.5, "0 (keep", 1.0);
    CHECK_REFUSED(m, "surface_mode", NAN, "NaN", 1.0);
    CHECK_REFUSED(m, "feature_angle", 0, "(0, 180)", 30.0);
    CHECK_REFUSED(m, "feature_angle", 200, "(0, 180)", 30.0);
    CHECK_REFUSED(m, "feature_angle", 180, "(0, 180)", 30.0);
    CHECK_REFUSED(m, "feature_angle", -10, "(0, 180)", 30.0);
    CHECK_REFUSED(m, "feature_angle", INFINITY, "(0, 180)", 30.0);
    CHECK_REFUSED(m, "surface_distance", -1, ">= 0", 0.01);
    CHECK_REFUSED(m, "surface_distance", INFINITY, "finite", 0.01);
    CHECK_REFUSED(m, "surface_distance", NAN, "NaN", 0.01);

    /* A wrong name lists the new ones among the valid names. */
    CHECK_STATUS(m, sm_set_param(m, "surface", 1), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "surface_mode");
    CHECK_ERROR_HAS(m, "feature_angle");
    CHECK_ERROR_HAS(m, "surface_distance");
    v = -1;
    CHECK_STATUS(m, sm_get_param(m, "surface", &v), SM_ERR_INVALID_ARGUMENT);
    CHECK(v == -1);

    /* 0 is the default distance, accepted again. */
    CHECK_STATUS(m, sm_set_param(m, "surface_distance", 0), SM_OK);
    CHECK_PARAM(m, "surface_distance", 0.0);
    sm_destroy(m);
}

/* The unit cube's boundary as 12 triangles, outward, one marker: a closed triangulated surface
 * as an .off file gives it. */
static sm_mesher *make_triangulated_cube(void) {
    sm_mesher *m = sm_create();
    int k;
    if (m == NULL) {
        fprintf(stderr, "sm_create returned NULL\n");
        exit(1);
    }
    CHECK_STATUS(m, sm_add_vertices(m, CUBE_XYZ, 8), SM_OK);
    for (k = 0; k < 6; k++) {
        const uint32_t *q = CUBE_FACES[k];
        const uint32_t t1[3] = {q[0], q[1], q[2]};
        const uint32_t t2[3] = {q[0], q[2], q[3]};
        CHECK_STATUS(m, sm_add_facet(m, t1, 3, 1), SM_OK);
        CHECK_STATUS(m, sm_add_facet(m, t2, 3, 1), SM_OK);
    }
    return m;
}

/* Sum of the tets' signed volumes, or -1 when they cannot be read. */
static double mesh_volume(const sm_mesher *m) {
    size_t nv = sm_num_vertices(m), nt = sm_num_tets(m), i;
    double *xyz = (double *)malloc(3 * nv * sizeof(double));
    uint32_t *tets = (uint32_t *)malloc(4 * nt * sizeof(uint32_t));
    double volume = -1;
    if (xyz != NULL && tets != NULL && sm_get_vertices(m, xyz, nv) == SM_OK &&
        sm_get_tets(m, tets, NULL, nt) == SM_OK) {
        volume = 0;
        for (i = 0; i < nt; i++) {
            volume += tet_volume(xyz, tets + 4 * i);
        }
    }
    free(xyz);
    free(tets);
    return volume;
}

/* The default surface mode is keep: the triangulated cube meshes exactly. */
static void test_keep_is_the_default(void) {
    sm_mesher *m = make_triangulated_cube();
    sm_status s;
    CHECK_STATUS(m, sm_set_spacing_const(m, 0.3), SM_OK);
    s = sm_refine(m);
    CHECK_STATUS(m, s, SM_OK);
    if (s == SM_OK) {
        CHECK(sm_num_tets(m) > 0);
        CHECK(fabs(mesh_volume(m) - 1.0) < 1e-9);
    }
    sm_destroy(m);
}

#if SM_TEST_APPROX_RUN
/* Approximate mode on the triangulated cube (its 12 edges are sharp features at 90 degrees). */
static void test_approximate_run(void) {
    sm_mesher *m = make_triangulated_cube();
    sm_status s;
    CHECK_STATUS(m, sm_set_param(m, "surface_mode", 1), SM_OK);
    CHECK_STATUS(m, sm_set_spacing_const(m, 0.3), SM_OK);
    s = sm_refine(m);
    CHECK(s == SM_OK);
    if (s == SM_OK) {
        /* The cube is its own approximation: the volume is exact up to rounding. */
        double volume = mesh_volume(m);
        CHECK(sm_num_tets(m) > 0);
        CHECK(fabs(volume - 1.0) < 1e-9);
        printf("approximate mode: %lu tets, volume %.12f\n", (unsigned long)sm_num_tets(m),
               volume);
    } else {
        printf("approximate mode failed: %s: %s\n", sm_status_str(s), sm_last_error(m));
    }
    sm_destroy(m);
}
#endif

int main(void) {
    test_surface_params();
    test_keep_is_the_default();
#if SM_TEST_APPROX_RUN
    test_approximate_run();
#endif
    return finish("test_surface");
}
