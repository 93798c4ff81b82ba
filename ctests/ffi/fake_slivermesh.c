/* A stand-in libslivermesh.so with the right SONAME that also exports a symbol without the sm_
 * prefix: ffi_shared_library_detects_leaked_symbol checks that shared_library.sh rejects it. */
const char *sm_version(void);
int leaked_helper(void);

const char *sm_version(void) { return "0.0.0"; }
int leaked_helper(void) { return 1; }
