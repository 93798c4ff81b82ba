/* The batched spacing callback during refinement: a graded unit cube of about 10^6 tets
 * meshed with a batched callback that counts its calls and points (calls must be at most a
 * tenth of the points: refinement evaluates the spacing of the tets one insertion creates in
 * one call), then with the same function as a per-point callback: the two meshes are the same
 * (tet and vertex counts, checksums of the vertex coordinates and of the tets). */
#include "common.h"

#include <stdint.h>

/* Fine at the origin corner, coarse away from it. */
static double graded(double x, double y, double z) {
    return 0.0055 + 0.014 * sqrt(x * x + y * y + z * z);
}

typedef struct {
    size_t calls;
    size_t points;
} counts;

static void batch_fn(size_t n, const double *xyz, double *out, void *user_data) {
    counts *c = (counts *)user_data;
    size_t i;
    c->calls++;
    c->points += n;
    for (i = 0; i < n; i++) {
        out[i] = graded(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    }
}

static double point_fn(double x, double y, double z, void *user_data) {
    size_t *calls = (size_t *)user_data;
    (*calls)++;
    return graded(x, y, z);
}

/* FNV-1a over n bytes, continuing from h. */
static uint64_t fnv(uint64_t h, const void *data, size_t n) {
    const unsigned char *p = (const unsigned char *)data;
    size_t i;
    for (i = 0; i < n; i++) {
        h = (h ^ p[i]) * 1099511628211ULL;
    }
    return h;
}

typedef struct {
    size_t n_vertices, n_tets;
    uint64_t vertex_sum, tet_sum;
} summary;

static summary summarize(const sm_mesher *m) {
    summary s;
    double *xyz;
    uint32_t *tets;
    s.n_vertices = sm_num_vertices(m);
    s.n_tets = sm_num_tets(m);
    xyz = (double *)malloc(3 * s.n_vertices * sizeof(double));
    tets = (uint32_t *)malloc(4 * s.n_tets * sizeof(uint32_t));
    if (xyz == NULL || tets == NULL) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    CHECK_STATUS(m, sm_get_vertices(m, xyz, s.n_vertices), SM_OK);
    CHECK_STATUS(m, sm_get_tets(m, tets, NULL, s.n_tets), SM_OK);
    s.vertex_sum = fnv(14695981039346656037ULL, xyz, 3 * s.n_vertices * sizeof(double));
    s.tet_sum = fnv(14695981039346656037ULL, tets, 4 * s.n_tets * sizeof(uint32_t));
    free(xyz);
    free(tets);
    return s;
}

int main(void) {
    counts batched = {0, 0};
    size_t point_calls = 0;
    summary a, b;
    sm_mesher *m = make_cube();
    sm_status s;

    CHECK_STATUS(m, sm_set_spacing_batch_cb(m, batch_fn, &batched), SM_OK);
    s = sm_refine(m);
    if (mesh_pending(m, s)) {
        sm_destroy(m);
        return SKIP_CODE;
    }
    CHECK_STATUS(m, s, SM_OK);
    a = summarize(m);
    printf("batched callback: %zu tets, %zu vertices; %zu calls for %zu points "
           "(%.1f points per call)\n",
           a.n_tets, a.n_vertices, batched.calls, batched.points,
           batched.calls ? (double)batched.points / (double)batched.calls : 0.0);
    CHECK(a.n_tets >= 700000);
    CHECK(batched.points > 0);
    CHECK(10 * batched.calls <= batched.points);

    CHECK_STATUS(m, sm_set_spacing_cb(m, point_fn, &point_calls), SM_OK);
    CHECK_STATUS(m, sm_refine(m), SM_OK);
    b = summarize(m);
    printf("per-point callback: %zu tets, %zu vertices; %zu calls\n", b.n_tets, b.n_vertices,
           point_calls);
    printf("checksums: vertices %016llx / %016llx, tets %016llx / %016llx\n",
           (unsigned long long)a.vertex_sum, (unsigned long long)b.vertex_sum,
           (unsigned long long)a.tet_sum, (unsigned long long)b.tet_sum);
    CHECK(a.n_tets == b.n_tets);
    CHECK(a.n_vertices == b.n_vertices);
    CHECK(a.vertex_sum == b.vertex_sum);
    CHECK(a.tet_sum == b.tet_sum);
    /* The same points are evaluated either way. */
    CHECK(point_calls == batched.points);

    sm_destroy(m);
    return finish("test_spacing_batch");
}
