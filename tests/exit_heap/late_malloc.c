/* Allocator traffic at exit, after the FMU library's own exit code: what numpy's
   libgfortran and the OpenBLAS thread do in a real host. Loaded after the FMU, so its
   destructor runs after the FMU's; it walks malloc's bins, and aborts the process if
   the FMU left a freed block's free-list pointer corrupted. */
#include <stdlib.h>

__attribute__((destructor)) static void late_malloc(void) {
    void *p[256];
    for (int i = 0; i < 256; i++) p[i] = malloc(i % 8 ? 128 : 4000);
    for (int i = 0; i < 256; i++) free(p[i]);
}
