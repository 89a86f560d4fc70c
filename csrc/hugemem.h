/* hugemem.h -- allocation of the large arrays that the event loop reads at random.
 *
 * At N = 1e5 .. 1e6 the per-particle arrays, the cell heads and the queue take tens of
 * MB and each event touches a few dozen random places in them.  With 4 KiB pages most
 * of those touches also miss the TLB, and the page walk is itself a cache miss; 2 MiB
 * pages cover the whole working set with a few dozen TLB entries.  Linux backs memory
 * with them when asked (madvise, the default THP setting); elsewhere, or when refused,
 * this is a plain aligned allocation.  Free with free(). */
#ifndef GR_HUGEMEM_H
#define GR_HUGEMEM_H

#include <stdlib.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#define GR_HUGE_PAGE ((size_t)2 << 20)

/* bytes (>= 1) aligned to 64 (a cache line), or to a huge page when at least one */
static inline void *gr_big_alloc(size_t bytes)
{
    void *p = NULL;
    if (bytes == 0) bytes = 1;
    if (posix_memalign(&p, bytes >= GR_HUGE_PAGE ? GR_HUGE_PAGE : 64, bytes) != 0) return NULL;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (bytes >= GR_HUGE_PAGE) (void)madvise(p, bytes, MADV_HUGEPAGE); /* a hint: failure is fine */
#endif
    return p;
}

#endif
