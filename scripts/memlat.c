/* How far this machine's caches reach: sequential read bandwidth and the
 * latency of dependent random reads (a pointer chase over one 64-byte line
 * per step) for working sets from 64 KB to 256 MB. This VM's perf has no
 * cache counters; where the latency jumps is the cache a pass over that much
 * data sees (BENCHMARKS.md, "Bounds, copies and masks").
 *
 *   gcc -O2 scripts/memlat.c -o /tmp/memlat && /tmp/memlat
 *   HUGE=1 /tmp/memlat     # the buffers in transparent huge pages (madvise)
 */
#define _GNU_SOURCE
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

int main(void) {
    const size_t kb[] = {64, 256, 768, 2048, 4096, 8192, 12288, 16384, 24576, 32768, 65536, 262144};
    const size_t page = 2u << 20;
    printf("working set   sequential read   random read latency\n");
    for (size_t s = 0; s < sizeof kb / sizeof kb[0]; s++) {
        size_t bytes = kb[s] << 10, alloc = (bytes + page - 1) / page * page;
        double *a = aligned_alloc(page, alloc);
        if (!a) return 2;
        if (getenv("HUGE")) madvise(a, alloc, MADV_HUGEPAGE);
        size_t n = bytes / 8;
        for (size_t i = 0; i < n; i++) a[i] = (double)i;
        /* sequential: sum the buffer until 4 GB have been read */
        double sum = 0, t0 = now();
        size_t read = 0;
        while (read < ((size_t)4 << 30)) {
            for (size_t i = 0; i < n; i += 8)
                sum += a[i] + a[i + 1] + a[i + 2] + a[i + 3] + a[i + 4] + a[i + 5] + a[i + 6] + a[i + 7];
            read += bytes;
        }
        double bw = read / (now() - t0) / 1e9;
        /* random: one cycle through every line in a shuffled order */
        size_t lines = bytes / 64;
        uint32_t *perm = malloc(lines * sizeof *perm);
        if (!perm) return 2;
        for (size_t i = 0; i < lines; i++) perm[i] = (uint32_t)i;
        uint64_t x = 88172645463325252ull;
        for (size_t i = lines - 1; i > 0; i--) {
            x ^= x << 13, x ^= x >> 7, x ^= x << 17;
            size_t j = x % (i + 1);
            uint32_t t = perm[i];
            perm[i] = perm[j], perm[j] = t;
        }
        size_t *next = (size_t *)a;
        for (size_t i = 0; i < lines; i++) next[perm[i] * 8] = perm[(i + 1) % lines] * 8;
        size_t p = 0, steps = 20000000;
        t0 = now();
        for (size_t i = 0; i < steps; i++) p = next[p];
        double lat = (now() - t0) / steps * 1e9;
        printf("%8zu KB   %7.1f GB/s      %7.1f ns%s\n", kb[s], bw, lat, (p == 1 && sum < 0) ? " " : "");
        free(perm);
        free(a);
    }
    return 0;
}
