/*
 * Sanitizer builds only: keeps a window context's GL driver mapped until exit, so
 * LeakSanitizer still sees the driver's globals. Mesa (swrast_dri.so) keeps
 * about 240 bytes reachable only from its globals; glfwTerminate unloads it
 * and LSan would report them from "<unknown module>", which no suppression
 * can name. Normal builds compile this to nothing.
 */
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ASP_GL_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define ASP_GL_ASAN 1
#endif

#ifdef ASP_GL_ASAN
#define _GNU_SOURCE 1 /* dladdr, RTLD_NOLOAD, RTLD_NODELETE */
#include <dlfcn.h>
#endif

#include "render/internal.h"
#include "util/banned.h"

void asp__gl_pin_driver(void)
{
#ifdef ASP_GL_ASAN
    /*
     * GL_VENDOR is a constant string inside the driver that implements the
     * context, whatever dispatch layer (GLVND) sits in front of it, so its
     * address names the driver's file. Another reference with RTLD_NODELETE
     * makes the later dlclose leave it mapped.
     */
    const GLubyte *vendor = glGetString(GL_VENDOR);
    Dl_info info;
    if (vendor && dladdr(vendor, &info) && info.dli_fname)
        dlopen(info.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
#endif
}
