/* Which threads call a spacing callback (issue 39 item 5). A graded unit cube (about 10^5 tets)
 * is meshed with "threads" = 4 and callbacks that count the calls in flight (a C11 atomic
 * incremented on entry, decremented on exit after a short spin, the maximum kept) and the calls
 * made from a thread other than the one calling sm_refine:
 *  - not declared thread-safe ("spacing_thread_safe" 0, the default), per-point and batched:
 *    never two calls at once, and every call from the calling thread (asserted);
 *  - declared thread-safe, batched: the big batches may be split across the run's threads;
 *    how many calls overlapped and how many came from other threads is printed, not asserted
 *    (two threads may simply not overlap on a loaded machine); with "threads" 1 every call is
 *    from the calling thread (asserted). The mesh is the same in every case (asserted:
 *    checksums of the vertices and tets). */
#include "common.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

static atomic_int g_in_flight;
static atomic_int g_max_in_flight;
static atomic_long g_calls;
static atomic_long g_off_thread;
static pthread_t g_caller;

static double graded(double x, double y, double z) {
    return 0.02 + 0.05 * sqrt(x * x + y * y + z * z);
}

/* Entering a call: counts it, notes the most calls in flight and a call from another thread. */
static void enter(void) {
    int now = atomic_fetch_add(&g_in_flight, 1) + 1;
    int seen = atomic_load(&g_max_in_flight);
    while (now > seen && !atomic_compare_exchange_weak(&g_max_in_flight, &seen, now)) {
    }
    atomic_fetch_add(&g_calls, 1);
    if (!pthread_equal(pthread_self(), g_caller)) {
        atomic_fetch_add(&g_off_thread, 1);
    }
}

/* Leaving a call, after a short spin that widens the window in which calls could overlap. */
static void leave(int spins) {
    volatile int sink = 0;
    int i;
    for (i = 0; i < spins; i++) {
        sink += i;
    }
    (void)sink;
    atomic_fetch_sub(&g_in_flight, 1);
}

static double point_fn(double x, double y, double z, void *user_data) {
    double h;
    (void)user_data;
    enter();
    h = graded(x, y, z);
    leave(200);
    return h;
}

static void batch_fn(size_t n, const double *xyz, double *out, void *user_data) {
    size_t i;
    (void)user_data;
    enter();
    for (i = 0; i < n; i++) {
        out[i] = graded(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    }
    leave(1000 * (int)n);
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
    size_t n_tets;
    uint64_t checksum;
    int max_in_flight;
    long calls, off_thread;
} outcome;

/* Meshes the cube on `threads` threads with the callback (batched or per point), declared
 * thread-safe or not. */
static outcome run(int batched, int thread_safe, double threads) {
    outcome o = {0, 0, 0, 0, 0};
    sm_mesher *m = make_cube();
    size_t nv;
    double *xyz;
    uint32_t *tets;
    sm_status s;
    atomic_store(&g_in_flight, 0);
    atomic_store(&g_max_in_flight, 0);
    atomic_store(&g_calls, 0);
    atomic_store(&g_off_thread, 0);
    g_caller = pthread_self();
    CHECK_STATUS(m, sm_set_param(m, "threads", threads), SM_OK);
    CHECK_STATUS(m, sm_set_param(m, "spacing_thread_safe", thread_safe), SM_OK);
    if (batched) {
        CHECK_STATUS(m, sm_set_spacing_batch_cb(m, batch_fn, NULL), SM_OK);
    } else {
        CHECK_STATUS(m, sm_set_spacing_cb(m, point_fn, NULL), SM_OK);
    }
    s = sm_refine(m);
    CHECK_STATUS(m, s, SM_OK);
    if (s == SM_OK) {
        nv = sm_num_vertices(m);
        o.n_tets = sm_num_tets(m);
        xyz = (double *)malloc(3 * nv * sizeof(double));
        tets = (uint32_t *)malloc(4 * o.n_tets * sizeof(uint32_t));
        if (xyz == NULL || tets == NULL) {
            fprintf(stderr, "out of memory\n");
            exit(1);
        }
        CHECK_STATUS(m, sm_get_vertices(m, xyz, nv), SM_OK);
        CHECK_STATUS(m, sm_get_tets(m, tets, NULL, o.n_tets), SM_OK);
        o.checksum = fnv(14695981039346656037ULL, xyz, 3 * nv * sizeof(double));
        o.checksum = fnv(o.checksum, tets, 4 * o.n_tets * sizeof(uint32_t));
        free(xyz);
        free(tets);
    }
    o.max_in_flight = atomic_load(&g_max_in_flight);
    o.calls = atomic_load(&g_calls);
    o.off_thread = atomic_load(&g_off_thread);
    printf("%-9s callback, spacing_thread_safe %d, threads %g: %zu tets, checksum %016llx; "
           "%ld calls, at most %d at once, %ld from other threads\n",
           batched ? "batched" : "per-point", thread_safe, threads, o.n_tets,
           (unsigned long long)o.checksum, o.calls, o.max_in_flight, o.off_thread);
    sm_destroy(m);
    return o;
}

int main(void) {
    outcome point = run(0, 0, 4);
    outcome batch = run(1, 0, 4);
    outcome shared = run(1, 1, 4);
    outcome one = run(1, 1, 1);

    CHECK(point.n_tets >= 20000);
    /* Not declared thread-safe: one call at a time, all from the thread calling sm_refine. */
    CHECK(point.calls > 0 && point.max_in_flight == 1 && point.off_thread == 0);
    CHECK(batch.calls > 0 && batch.max_in_flight == 1 && batch.off_thread == 0);
    /* Declared thread-safe: whatever the overlap, the same mesh. */
    CHECK(shared.calls > 0);
    CHECK(one.off_thread == 0 && one.max_in_flight == 1);
    printf("declared thread-safe, 4 threads: %s (at most %d calls at once, %ld of %ld calls "
           "from other threads)\n",
           shared.max_in_flight > 1 || shared.off_thread > 0 ? "called from several threads"
                                                             : "no concurrent call seen",
           shared.max_in_flight, shared.off_thread, shared.calls);
    CHECK(batch.n_tets == point.n_tets && batch.checksum == point.checksum);
    CHECK(shared.n_tets == point.n_tets && shared.checksum == point.checksum);
    CHECK(one.n_tets == point.n_tets && one.checksum == point.checksum);
    return finish("test_spacing_threads");
}
