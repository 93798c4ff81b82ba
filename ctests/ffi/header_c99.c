/* include/slivermesh.h compiles as strict C99 (-std=c99 -pedantic -Wall -Wextra -Werror) and
 * declares what the contract says (a type error here fails the build). */
#include "slivermesh.h"

#include <stdio.h>

#if SIZE_MAX == UINT64_MAX
/* The Fortran module (include/slivermesh.f90) and the Rust tests check the same size. */
typedef char sm_quality_is_168_bytes[sizeof(sm_quality) == 168 ? 1 : -1];
typedef char sm_region_is_40_bytes[sizeof(sm_region) == 40 ? 1 : -1];
#endif

static double size_fn(double x, double y, double z, void *user_data) {
    (void)user_data;
    return 0.1 + 0.0 * (x + y + z);
}

static void batch_fn(size_t n, const double *xyz, double *out, void *user_data) {
    size_t i;
    (void)xyz;
    (void)user_data;
    for (i = 0; i < n; i++) out[i] = 0.1;
}

static int32_t progress_fn(double fraction, size_t n_vertices, void *user_data) {
    (void)fraction;
    (void)n_vertices;
    (void)user_data;
    return 0;
}

int main(void) {
    sm_spacing_fn f = size_fn;
    sm_spacing_batch_fn g = batch_fn;
    sm_progress_fn p = progress_fn;
    sm_quality q;
    sm_status s = SM_OK;
    sm_mesher *m = sm_create();
    const sm_mesher *cm = m;
    s |= sm_set_spacing_cb(m, f, NULL);
    s |= sm_set_spacing_batch_cb(m, g, NULL);
    s |= sm_set_progress_cb(m, p, NULL);
    q.n_tets = sm_num_tets(cm);
    q.complete = 0;
    /* Before sm_refine: no regions, and asking for them is an error naming it. */
    if (sm_num_regions(cm) != 0 ||
        sm_get_regions(cm, (sm_region *)NULL, 0, (double *)NULL, (double *)NULL) != SM_ERR_NOT_REFINED) {
        return 1;
    }
    printf("slivermesh %s (C99), status %d, %zu tets, complete %d\n", sm_version(), (int)s,
           q.n_tets, (int)q.complete);
    sm_destroy(m);
    return s == SM_OK ? 0 : 1;
}
