/* Every function of the C ABI and every error path that needs no mesh: NULL handle, NULL
 * arrays, bad vertex ids, NaN coordinates, bad parameters, outputs before sm_refine, spacing
 * callbacks returning 0 or NaN, cancel from the progress callback, static strings. */
#include "common.h"

static double spacing_nan_at_top(double x, double y, double z, void *user_data) {
    int *calls = (int *)user_data;
    (*calls)++;
    (void)x;
    (void)y;
    return z > 0.5 ? NAN : 0.25;
}

static double spacing_zero(double x, double y, double z, void *user_data) {
    (void)x;
    (void)y;
    (void)z;
    (void)user_data;
    return 0.0;
}

static void batch_negative_at_origin(size_t n, const double *xyz, double *out, void *user_data) {
    size_t i;
    size_t *batches = (size_t *)user_data;
    (*batches)++;
    for (i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        out[i] = (p[0] == 0 && p[1] == 0 && p[2] == 0) ? -1.0 : 0.3;
    }
}

static void batch_writes_nothing(size_t n, const double *xyz, double *out, void *user_data) {
    (void)n;
    (void)xyz;
    (void)out;
    (void)user_data;
}

struct progress_log {
    int calls;
    double first_fraction;
    size_t first_n;
};

static int32_t progress_cancel(double fraction, size_t n_vertices, void *user_data) {
    struct progress_log *log = (struct progress_log *)user_data;
    if (log->calls++ == 0) {
        log->first_fraction = fraction;
        log->first_n = n_vertices;
    }
    return 1;
}

static void test_static_strings(void) {
    sm_status s;
    CHECK(strcmp(sm_status_str(SM_OK), "ok") == 0);
    for (s = SM_OK; s <= SM_ERR_BUSY; s++) {
        CHECK(sm_status_str(s) != NULL && strcmp(sm_status_str(s), "unknown status") != 0);
    }
    CHECK(strcmp(sm_status_str(-1), "unknown status") == 0);
    CHECK(strcmp(sm_status_str(1000), "unknown status") == 0);
    CHECK(sm_version() != NULL && strchr(sm_version(), '.') != NULL);
    /* The numbering is part of the ABI. */
    CHECK(SM_OK == 0 && SM_ERR_NULL == 1 && SM_ERR_INVALID_ARGUMENT == 2);
    CHECK(SM_ERR_INVALID_INPUT == 3 && SM_ERR_SPACING == 4 && SM_ERR_CANCELLED == 5);
    CHECK(SM_ERR_BUFFER_TOO_SMALL == 6 && SM_ERR_NOT_REFINED == 7 && SM_ERR_IO == 8);
    CHECK(SM_ERR_PANIC == 9 && SM_ERR_POISONED == 10 && SM_ERR_INTERNAL == 11);
    CHECK(SM_ERR_BUSY == 12);
}

static void test_null_handle(void) {
    sm_mesher *m = NULL;
    const uint32_t ids[3] = {0, 1, 2};
    double xyz[3] = {0, 0, 0}, v = 0;
    uint32_t tets[4];
    int32_t regions[1];
    sm_quality q;
    sm_destroy(NULL); /* no-op */
    CHECK(sm_add_vertices(m, xyz, 1) == SM_ERR_NULL);
    CHECK(sm_add_facet(m, ids, 3, 0) == SM_ERR_NULL);
    CHECK(sm_add_facet_hole(m, ids, 3) == SM_ERR_NULL);
    CHECK(sm_add_hole(m, 0, 0, 0) == SM_ERR_NULL);
    CHECK(sm_add_region(m, 0, 0, 0, 1, 0) == SM_ERR_NULL);
    CHECK(sm_set_spacing_cb(m, spacing_zero, NULL) == SM_ERR_NULL);
    CHECK(sm_set_spacing_batch_cb(m, batch_writes_nothing, NULL) == SM_ERR_NULL);
    CHECK(sm_set_spacing_const(m, 1.0) == SM_ERR_NULL);
    CHECK(sm_set_param(m, "rho0", 2.0) == SM_ERR_NULL);
    CHECK(sm_get_param(m, "rho0", &v) == SM_ERR_NULL);
    CHECK(sm_set_progress_cb(m, progress_cancel, NULL) == SM_ERR_NULL);
    CHECK(sm_refine(m) == SM_ERR_NULL);
    CHECK(sm_num_vertices(m) == 0 && sm_num_tets(m) == 0 && sm_num_boundary_faces(m) == 0);
    CHECK(sm_get_vertices(m, xyz, 1) == SM_ERR_NULL);
    CHECK(sm_get_tets(m, tets, regions, 1) == SM_ERR_NULL);
    CHECK(sm_get_boundary_faces(m, tets, regions, 1) == SM_ERR_NULL);
    CHECK(sm_get_quality(m, &q) == SM_ERR_NULL);
    CHECK(sm_write(m, "null.vtu") == SM_ERR_NULL);
    CHECK(sm_stop_reason(m) == NULL);
    CHECK(sm_last_error(m) != NULL && strstr(sm_last_error(m), "NULL") != NULL);
}

static void test_input_errors(void) {
    sm_mesher *m = make_cube();
    const double nan_xyz[6] = {2, 2, 2, 0.5, NAN, 0.5};
    const double inf_xyz[3] = {INFINITY, 0, 0};
    const double big_xyz[3] = {1e31, 0, 0};
    const uint32_t bad_ids[3] = {0, 1, 8};
    const uint32_t tri[3] = {0, 1, 2};

    CHECK_STATUS(m, sm_add_vertices(m, nan_xyz, 2), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "vertex 9");
    CHECK_ERROR_HAS(m, "NaN");
    CHECK_STATUS(m, sm_add_vertices(m, inf_xyz, 1), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "vertex 8");
    CHECK_STATUS(m, sm_add_vertices(m, big_xyz, 1), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "range");
    CHECK_STATUS(m, sm_add_vertices(m, NULL, 3), SM_ERR_NULL);
    CHECK_ERROR_HAS(m, "xyz");
    CHECK_STATUS(m, sm_add_vertices(m, NULL, 0), SM_OK);
    CHECK(strcmp(sm_last_error(m), "") == 0);

    /* Bad ids: the batch above was rejected whole, so id 8 is still out of range. */
    CHECK_STATUS(m, sm_add_facet(m, bad_ids, 3, 7), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "vertex id 8");
    CHECK_ERROR_HAS(m, "facet 6");
    CHECK_STATUS(m, sm_add_facet(m, tri, 2, 7), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "at least 3");
    CHECK_STATUS(m, sm_add_facet(m, NULL, 3, 7), SM_ERR_NULL);
    CHECK_STATUS(m, sm_add_facet_hole(m, bad_ids, 3), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "hole polygon of facet 5");
    CHECK_STATUS(m, sm_add_facet_hole(m, NULL, 3), SM_ERR_NULL);
    CHECK_STATUS(m, sm_add_hole(m, NAN, 0, 0), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "hole 0");
    CHECK_STATUS(m, sm_add_region(m, 0.5, 0.5, INFINITY, 1, 0), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "region 0");
    CHECK_STATUS(m, sm_add_region(m, 0.5, 0.5, 0.5, 1, NAN), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "max_size");
    CHECK_STATUS(m, sm_add_region(m, 0.5, 0.5, 0.5, 1, 0.2), SM_OK);
    CHECK_STATUS(m, sm_add_hole(m, 5, 5, 5), SM_OK);
    sm_destroy(m);

    m = sm_create();
    CHECK_STATUS(m, sm_add_facet_hole(m, tri, 3), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "before any facet");
    CHECK_STATUS(m, sm_add_facet(m, tri, 3, 0), SM_ERR_INVALID_ARGUMENT); /* no vertices yet */
    sm_destroy(m);
}

static void test_params(void) {
    sm_mesher *m = sm_create();
    double v = -1;
    const char bad_utf8[2] = {(char)0xff, 0};
    CHECK_STATUS(m, sm_get_param(m, "rho0", &v), SM_OK);
    CHECK(v == 2.0);
    CHECK_STATUS(m, sm_set_param(m, "rho0", 1.4), SM_OK);
    CHECK_STATUS(m, sm_get_param(m, "rho0", &v), SM_OK);
    CHECK(v == 1.4);
    CHECK_STATUS(m, sm_set_param(m, "B", 2.0), SM_OK);
    CHECK_STATUS(m, sm_get_param(m, "size_factor", &v), SM_OK);
    CHECK(v == 2.0);
    CHECK_STATUS(m, sm_set_param(m, "seed", 12345), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "max_vertices", 100000), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "max_tries", 10), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "refine", 0), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "sigma0", 0.03), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "delta", 0.2), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "b", 5), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "min_dihedral", 12), SM_OK);
    CHECK_STATUS(m, sm_get_param(m, "min_dihedral", &v), SM_OK);
    CHECK(v == 12.0);
    CHECK_STATUS(m, sm_get_param(m, "small_angle_reach", &v), SM_OK);
    CHECK(isinf(v) && v > 0); /* default: whole facets */
    CHECK_STATUS(m, sm_set_param(m, "small_angle_reach", 2), SM_OK);
    CHECK_STATUS(m, sm_get_param(m, "small_angle_reach", &v), SM_OK);
    CHECK(v == 2.0);
    CHECK_STATUS(m, sm_set_param(m, "small_angle_reach", INFINITY), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "small_angle_reach", 0), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "small_angle_reach");

    CHECK_STATUS(m, sm_set_param(m, "rh0", 2), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "\"rh0\"");
    CHECK_ERROR_HAS(m, "valid names: rho0, sigma0");
    CHECK_STATUS(m, sm_set_param(m, "rho0", 0.5), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "sqrt(6)/4");
    CHECK_STATUS(m, sm_set_param(m, "sigma0", 0.2), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_set_param(m, "delta", 1.0), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_set_param(m, "delta", 0.0), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_set_param(m, "min_dihedral", 80), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "70.5");
    CHECK_STATUS(m, sm_set_param(m, "seed", 0.5), SM_ERR_INVALID_ARGUMENT);
    CHECK_ERROR_HAS(m, "whole");
    CHECK_STATUS(m, sm_set_param(m, "max_tries", 0), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_set_param(m, "refine", 2), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_set_param(m, "b", NAN), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_set_param(m, NULL, 1), SM_ERR_NULL);
    CHECK_STATUS(m, sm_set_param(m, bad_utf8, 1), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_get_param(m, "rho0", NULL), SM_ERR_NULL);
    v = -1;
    CHECK_STATUS(m, sm_get_param(m, "nope", &v), SM_ERR_INVALID_ARGUMENT);
    CHECK(v == -1); /* untouched on error */
    CHECK_STATUS(m, sm_get_param(m, "rho0", &v), SM_OK);
    CHECK(v == 1.4); /* rejected values changed nothing */

    CHECK_STATUS(m, sm_set_spacing_const(m, 0), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_set_spacing_const(m, -1), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_set_spacing_const(m, NAN), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_set_spacing_const(m, INFINITY), SM_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(m, sm_set_spacing_const(m, 0.1), SM_OK);
    CHECK_STATUS(m, sm_set_spacing_cb(m, NULL, NULL), SM_OK); /* back to automatic */
    CHECK_STATUS(m, sm_set_spacing_batch_cb(m, NULL, NULL), SM_OK);
    CHECK_STATUS(m, sm_set_progress_cb(m, NULL, NULL), SM_OK);
    sm_destroy(m);
}

static void test_outputs_before_refine(void) {
    sm_mesher *m = make_cube();
    double xyz[24];
    uint32_t tets[4], tris[3];
    int32_t regions[1], markers[1];
    sm_quality q;
    memset(&q, 0x5a, sizeof q);
    CHECK(sm_num_vertices(m) == 0 && sm_num_tets(m) == 0 && sm_num_boundary_faces(m) == 0);
    CHECK_STATUS(m, sm_get_vertices(m, xyz, 8), SM_ERR_NOT_REFINED);
    CHECK_ERROR_HAS(m, "sm_get_vertices");
    CHECK_STATUS(m, sm_get_tets(m, tets, regions, 1), SM_ERR_NOT_REFINED);
    CHECK_STATUS(m, sm_get_boundary_faces(m, tris, markers, 1), SM_ERR_NOT_REFINED);
    CHECK_STATUS(m, sm_get_quality(m, &q), SM_ERR_NOT_REFINED);
    CHECK(q.n_tets == (size_t)0x5a5a5a5a5a5a5a5aULL); /* untouched */
    CHECK_STATUS(m, sm_write(m, "never.vtu"), SM_ERR_NOT_REFINED);
    CHECK(sm_stop_reason(m) == NULL);
    sm_destroy(m);
}

static void test_bad_spacing(void) {
    sm_mesher *m = make_cube();
    int calls = 0;
    size_t batches = 0;

    CHECK_STATUS(m, sm_set_spacing_cb(m, spacing_nan_at_top, &calls), SM_OK);
    CHECK_STATUS(m, sm_refine(m), SM_ERR_SPACING);
    CHECK_ERROR_HAS(m, "NaN");
    CHECK_ERROR_HAS(m, "(0, 0, 1)"); /* vertex 4, the first with z > 0.5 */
    CHECK(calls >= 1);
    CHECK(sm_num_tets(m) == 0);

    CHECK_STATUS(m, sm_set_spacing_cb(m, spacing_zero, NULL), SM_OK);
    CHECK_STATUS(m, sm_refine(m), SM_ERR_SPACING);
    CHECK_ERROR_HAS(m, "returned 0 at (0, 0, 0)");

    CHECK_STATUS(m, sm_set_spacing_batch_cb(m, batch_negative_at_origin, &batches), SM_OK);
    CHECK_STATUS(m, sm_refine(m), SM_ERR_SPACING);
    CHECK_ERROR_HAS(m, "returned -1 at (0, 0, 0)");
    CHECK(batches >= 1);

    CHECK_STATUS(m, sm_set_spacing_batch_cb(m, batch_writes_nothing, NULL), SM_OK);
    CHECK_STATUS(m, sm_refine(m), SM_ERR_SPACING);
    CHECK_ERROR_HAS(m, "NaN");
    sm_destroy(m);
}

static void test_cancel(void) {
    sm_mesher *m = make_cube();
    struct progress_log log = {0, -1.0, 0};
    CHECK_STATUS(m, sm_set_spacing_const(m, 0.3), SM_OK);
    CHECK_STATUS(m, sm_set_progress_cb(m, progress_cancel, &log), SM_OK);
    CHECK_STATUS(m, sm_refine(m), SM_ERR_CANCELLED);
    CHECK_ERROR_HAS(m, "cancelled");
    CHECK(log.calls == 1);
    CHECK(log.first_fraction == 0.0 && log.first_n == 8);
    CHECK(sm_num_tets(m) == 0);
    sm_destroy(m);
}

int main(void) {
    test_static_strings();
    test_null_handle();
    test_input_errors();
    test_params();
    test_outputs_before_refine();
    test_bad_spacing();
    test_cancel();
    return finish("test_api");
}
