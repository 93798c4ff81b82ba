// include/slivermesh.h compiles as C++ (-pedantic -Wall -Wextra -Werror), with C linkage, and
// its callbacks accept captureless lambdas.
#include "slivermesh.h"

#include <cstdio>
#include <memory>

int main() {
    std::unique_ptr<sm_mesher, decltype(&sm_destroy)> m(sm_create(), &sm_destroy);
    sm_spacing_fn f = [](double, double, double, void *) -> double { return 0.1; };
    sm_progress_fn p = [](double, size_t, void *) -> int32_t { return 0; };
    sm_status s = sm_set_spacing_cb(m.get(), f, nullptr);
    s |= sm_set_progress_cb(m.get(), p, nullptr);
    sm_quality q{};
    std::printf("slivermesh %s (C++), status %d (%s), %zu tets\n", sm_version(), int(s),
                sm_status_str(s), q.n_tets);
    return s == SM_OK ? 0 : 1;
}
