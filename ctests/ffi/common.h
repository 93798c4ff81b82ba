/* Shared helpers of the C ABI tests: checks that report file:line, the unit cube, and the
 * "refine::mesh is not implemented yet" skip (exit code 77, ctest SKIP_RETURN_CODE). */
#ifndef SLIVERMESH_CTEST_COMMON_H
#define SLIVERMESH_CTEST_COMMON_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "slivermesh.h"

#define SKIP_CODE 77

static int g_failures = 0;

#define CHECK(cond)                                                                  \
    do {                                                                             \
        if (!(cond)) {                                                               \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
            g_failures++;                                                            \
        }                                                                            \
    } while (0)

/* Status check that prints both codes and the handle's message on failure. */
#define CHECK_STATUS(m, call, want)                                                        \
    do {                                                                                   \
        sm_status got_ = (call);                                                           \
        if (got_ != (want)) {                                                              \
            fprintf(stderr, "%s:%d: %s returned %d (%s), want %d (%s); last error: %s\n",  \
                    __FILE__, __LINE__, #call, (int)got_, sm_status_str(got_), (int)(want), \
                    sm_status_str(want), sm_last_error(m));                                \
            g_failures++;                                                                  \
        }                                                                                  \
    } while (0)

/* The last error of m contains needle. */
#define CHECK_ERROR_HAS(m, needle)                                                       \
    do {                                                                                 \
        const char *e_ = sm_last_error(m);                                               \
        if (e_ == NULL || strstr(e_, (needle)) == NULL) {                                \
            fprintf(stderr, "%s:%d: last error \"%s\" lacks \"%s\"\n", __FILE__, __LINE__, \
                    e_ ? e_ : "(NULL)", (needle));                                       \
            g_failures++;                                                                \
        }                                                                                \
    } while (0)

static const double CUBE_XYZ[24] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,
                                    0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
static const uint32_t CUBE_FACES[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                          {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

/* The unit cube [0,1]^3 with facet markers 1..6. */
static inline sm_mesher *make_cube(void) {
    sm_mesher *m = sm_create();
    int k;
    if (m == NULL) {
        fprintf(stderr, "sm_create returned NULL\n");
        exit(1);
    }
    CHECK_STATUS(m, sm_add_vertices(m, CUBE_XYZ, 8), SM_OK);
    for (k = 0; k < 6; k++) {
        CHECK_STATUS(m, sm_add_facet(m, CUBE_FACES[k], 4, k + 1), SM_OK);
    }
    return m;
}

/* True (after saying so) when sm_refine failed only because refine::mesh is still a stub. */
static inline int mesh_pending(const sm_mesher *m, sm_status s) {
    if (s == SM_ERR_INTERNAL && strstr(sm_last_error(m), "not implemented yet") != NULL) {
        printf("SKIP: sm_refine: %s (waits on refine::mesh)\n", sm_last_error(m));
        return 1;
    }
    return 0;
}

/* Signed volume of the tet (a, b, c, d) given by vertex ids into xyz. */
static inline double tet_volume(const double *xyz, const uint32_t *t) {
    const double *a = xyz + 3 * t[0], *b = xyz + 3 * t[1], *c = xyz + 3 * t[2], *d = xyz + 3 * t[3];
    double u[3], v[3], w[3];
    int i;
    for (i = 0; i < 3; i++) {
        u[i] = b[i] - a[i];
        v[i] = c[i] - a[i];
        w[i] = d[i] - a[i];
    }
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
            u[2] * (v[0] * w[1] - v[1] * w[0])) /
           6.0;
}

static inline int finish(const char *name) {
    if (g_failures) {
        fprintf(stderr, "%s: %d check(s) failed\n", name, g_failures);
        return 1;
    }
    printf("%s: all checks passed\n", name);
    return 0;
}

#endif
