/* sm_refine_mpi from inside an MPI program (run under mpirun -np 2 or more by
 * tests/distributed.rs): every rank meshes its part of the unit cube; the parts' global
 * numbers must agree (a vertex held by several ranks has the same coordinates under one global
 * id), the tet ids must follow each other rank by rank, and every tet must be valid and meet
 * the improvement target. Built against a library with the cargo feature mpi. */
#define SLIVERMESH_MPI 1
#include <mpi.h>
#include <stdint.h>

#include "common.h"

int main(int argc, char **argv) {
    int rank, size, k;
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);

    /* Before any distributed run there are no global numbers. */
    sm_mesher *m = make_cube();
    uint64_t nv = 0, nt = 0, first = 0;
    CHECK_STATUS(m, sm_global_counts(m, &nv, &nt, &first), SM_ERR_NOT_REFINED);

    CHECK_STATUS(m, sm_set_spacing_const(m, 0.1), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "threads", 1), SM_OK);
    CHECK_STATUS(m, sm_refine_mpi(m, (int32_t)MPI_Comm_c2f(MPI_COMM_WORLD)), SM_OK);
    CHECK_STATUS(m, sm_global_counts(m, &nv, &nt, &first), SM_OK);

    size_t n = sm_num_vertices(m), tets = sm_num_tets(m);
    double *xyz = malloc(3 * n * sizeof(double));
    uint64_t *ids = malloc(n * sizeof(uint64_t));
    uint32_t *tv = malloc(4 * tets * sizeof(uint32_t));
    CHECK_STATUS(m, sm_get_vertices(m, xyz, n), SM_OK);
    CHECK_STATUS(m, sm_get_global_vertex_ids(m, ids, n), SM_OK);
    CHECK_STATUS(m, sm_get_tets(m, tv, NULL, tets), SM_OK);

    /* Tet ids: this rank's follow the lower ranks' (exclusive prefix sum), all add up. */
    uint64_t mine = tets, before = 0, total = 0;
    MPI_Exscan(&mine, &before, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    if (rank == 0) before = 0;
    MPI_Allreduce(&mine, &total, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    CHECK(first == before);
    CHECK(total == nt);

    /* Vertex ids: below the global count; one set of coordinates per id over all ranks. */
    double *global = malloc(3 * nv * sizeof(double));
    const double unset = -1e300; /* no coordinate (sliding leaves some at -1e-19, not 0) */
    for (k = 0; k < (int)(3 * nv); k++) global[k] = unset;
    for (size_t v = 0; v < n; v++) {
        CHECK(ids[v] < nv);
        if (ids[v] < nv) memcpy(global + 3 * ids[v], xyz + 3 * v, 3 * sizeof(double));
    }
    double *lo = malloc(3 * nv * sizeof(double)), *hi = malloc(3 * nv * sizeof(double));
    double *neg = malloc(3 * nv * sizeof(double));
    /* The max over ranks is the coordinate, and the min over the ranks holding it must be the
     * same. */
    MPI_Allreduce(global, hi, (int)(3 * nv), MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    for (k = 0; k < (int)(3 * nv); k++) neg[k] = global[k] == unset ? unset : -global[k];
    MPI_Allreduce(neg, lo, (int)(3 * nv), MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    int unheld = 0, mismatched = 0;
    for (k = 0; k < (int)(3 * nv); k++) {
        if (hi[k] == unset) unheld++;
        else if (-lo[k] != hi[k]) mismatched++;
    }
    CHECK(unheld == 0);
    CHECK(mismatched == 0);

    /* Every tet positive; the part's quality at the keep mode's improvement target. */
    size_t flat = 0;
    for (size_t t = 0; t < tets; t++) {
        if (!(tet_volume(xyz, tv + 4 * t) > 0)) flat++;
    }
    CHECK(flat == 0);
    sm_quality q;
    CHECK_STATUS(m, sm_get_quality(m, &q), SM_OK);
    CHECK(q.min_dihedral_deg >= 25.9);
    printf("rank %d of %d: %zu tets (first %llu of %llu), %zu vertices of %llu, min dihedral "
           "%.2f\n",
           rank, size, tets, (unsigned long long)first, (unsigned long long)nt, n,
           (unsigned long long)nv, q.min_dihedral_deg);

    /* A serial run afterwards drops the global numbers. */
    CHECK_STATUS(m, sm_refine(m), SM_OK);
    CHECK_STATUS(m, sm_global_counts(m, &nv, &nt, &first), SM_ERR_NOT_REFINED);

    sm_destroy(m);
    free(xyz); free(ids); free(tv); free(global); free(lo); free(hi); free(neg);
    int failures = g_failures, any = 0;
    MPI_Allreduce(&failures, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Finalize();
    if (any == 0 && rank == 0) printf("sm_refine_mpi: all checks passed on %d ranks\n", size);
    return any ? 1 : 0;
}
