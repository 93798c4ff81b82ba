/* A minimal program linked against the installed shared library: the header's SM_VERSION_*
 * macros must name the library it runs with (sm_version()), and a handle must work. */
#include <slivermesh.h>
#include <stdio.h>
#include <string.h>

#define SM_STR2(x) #x
#define SM_STR(x) SM_STR2(x)

int main(void) {
    const char *header = SM_STR(SM_VERSION_MAJOR) "." SM_STR(SM_VERSION_MINOR) "." SM_STR(
        SM_VERSION_PATCH);
    const char *lib = sm_version();
    sm_mesher *m;
    if (strcmp(header, lib) != 0) {
        fprintf(stderr, "FAIL: header version %s, library version %s\n", header, lib);
        return 1;
    }
    m = sm_create();
    if (!m || sm_set_spacing_const(m, 0.5) != SM_OK) {
        fprintf(stderr, "FAIL: sm_create/sm_set_spacing_const\n");
        return 1;
    }
    sm_destroy(m);
    printf("version_consumer: header %s == library %s\n", header, lib);
    return 0;
}
