/* Two threads, each with its own handle, building and meshing at the same time (with spacing
 * and progress callbacks whose user data is per thread), and hitting error paths at the same
 * time. Run under AddressSanitizer. The meshing part waits on refine::mesh (exit 77 while
 * sm_refine reports "not implemented yet"); the rest runs now. */
#include <pthread.h>

#include "common.h"

struct job {
    double h0;   /* spacing at x = 0 */
    int calls;   /* spacing callback calls, this thread only */
    int reports; /* progress callback calls */
    int pending; /* sm_refine is still a stub */
    int failures;
    size_t n_tets;
    double volume;
};

static double spacing(double x, double y, double z, void *user_data) {
    struct job *j = (struct job *)user_data;
    (void)y;
    (void)z;
    j->calls++;
    return j->h0 * (1.0 + x);
}

static int32_t progress(double fraction, size_t n_vertices, void *user_data) {
    struct job *j = (struct job *)user_data;
    (void)fraction;
    (void)n_vertices;
    j->reports++;
    return 0;
}

#define JOB_CHECK(j, cond)                                                              \
    do {                                                                                \
        if (!(cond)) {                                                                  \
            fprintf(stderr, "%s:%d: thread check failed: %s\n", __FILE__, __LINE__, #cond); \
            (j)->failures++;                                                            \
        }                                                                               \
    } while (0)

static void *run(void *arg) {
    struct job *j = (struct job *)arg;
    int round;
    for (round = 0; round < 3; round++) {
        sm_mesher *m = sm_create();
        const double nan_xyz[3] = {NAN, 0, 0};
        sm_status s;
        int k;
        JOB_CHECK(j, m != NULL);
        JOB_CHECK(j, sm_add_vertices(m, CUBE_XYZ, 8) == SM_OK);
        for (k = 0; k < 6; k++) {
            JOB_CHECK(j, sm_add_facet(m, CUBE_FACES[k], 4, k + 1) == SM_OK);
        }
        /* Errors in one thread must not leak into the other's messages. */
        JOB_CHECK(j, sm_add_vertices(m, nan_xyz, 1) == SM_ERR_INVALID_ARGUMENT);
        JOB_CHECK(j, strstr(sm_last_error(m), "vertex 8") != NULL);
        JOB_CHECK(j, sm_set_param(m, "seed", 1 + round) == SM_OK);
        JOB_CHECK(j, strcmp(sm_last_error(m), "") == 0);
        JOB_CHECK(j, sm_set_spacing_cb(m, spacing, j) == SM_OK);
        JOB_CHECK(j, sm_set_progress_cb(m, progress, j) == SM_OK);
        s = sm_refine(m);
        if (s == SM_ERR_INTERNAL && strstr(sm_last_error(m), "not implemented yet")) {
            j->pending = 1;
        } else {
            size_t nv = sm_num_vertices(m), nt = sm_num_tets(m), i;
            double *xyz = (double *)malloc(3 * nv * sizeof *xyz);
            uint32_t *tets = (uint32_t *)malloc(4 * nt * sizeof *tets);
            JOB_CHECK(j, s == SM_OK);
            JOB_CHECK(j, sm_get_vertices(m, xyz, nv) == SM_OK);
            JOB_CHECK(j, sm_get_tets(m, tets, NULL, nt) == SM_OK);
            j->volume = 0;
            for (i = 0; i < nt; i++) {
                j->volume += tet_volume(xyz, tets + 4 * i);
            }
            j->n_tets = nt;
            free(xyz);
            free(tets);
        }
        JOB_CHECK(j, j->calls > 0 && j->reports > 0);
        sm_destroy(m);
    }
    return NULL;
}

int main(void) {
    struct job jobs[2] = {{0.15, 0, 0, 0, 0, 0, 0.0}, {0.25, 0, 0, 0, 0, 0, 0.0}};
    pthread_t threads[2];
    int i;
    for (i = 0; i < 2; i++) {
        CHECK(pthread_create(&threads[i], NULL, run, &jobs[i]) == 0);
    }
    for (i = 0; i < 2; i++) {
        CHECK(pthread_join(threads[i], NULL) == 0);
        g_failures += jobs[i].failures;
        if (!jobs[i].pending) {
            printf("thread %d: %zu tets, volume %.15f\n", i, jobs[i].n_tets, jobs[i].volume);
            CHECK(jobs[i].n_tets > 0 && fabs(jobs[i].volume - 1.0) < 1e-9);
        }
    }
    if (!jobs[0].pending && !jobs[1].pending) {
        CHECK(jobs[0].n_tets > jobs[1].n_tets); /* the finer spacing gives more tets */
    }
    if (g_failures == 0 && (jobs[0].pending || jobs[1].pending)) {
        printf("test_threads: handles worked concurrently; meshing waits on refine::mesh\n");
        return SKIP_CODE;
    }
    return finish("test_threads");
}
