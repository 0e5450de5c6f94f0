/* keep_libraries_loaded.c: an LD_PRELOAD shim for the sanitizer test run (make test SAN=1)
 * that turns dlclose() into a no-op, so no shared library is ever unmapped.
 *
 * Why: eglTerminate() makes Mesa dlclose() its DRI driver (swrast_dri.so, which holds
 * llvmpipe and LLVM). The driver leaves a few small allocations behind, and once it is
 * unmapped LeakSanitizer can only print "(<unknown module>)" for them: no suppression
 * can name a library that is gone, and frames in it cannot be told from ours. With the
 * driver kept mapped, its globals still point at those blocks (so they are not leaks
 * at all), and any leak that is left names its library, which tests/sanitizers/lsan.supp
 * can then suppress by name. Keeping a library loaded changes nothing else: a later
 * dlopen() of it just finds it already there.
 *
 * Preloaded into every process of the test run (sh, sed, ... too), where it is harmless;
 * the sanitized programs need ASAN_OPTIONS=verify_asan_link_order=0 because the shim
 * then comes before the ASan runtime in the library list. */
#include <dlfcn.h>

/* Reports success without unloading anything (see above). */
int dlclose(void *handle)
{
    (void)handle;
    return 0;
}
