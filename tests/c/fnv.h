/* FNV-1a over bytes, the hash of the golden-output tests (test_golden, test_first_order_off):
 * a run's results hashed bit for bit, so that a reshaping that changes one bit shows. */
#ifndef GALPHA_TESTS_FNV_H
#define GALPHA_TESTS_FNV_H

#include <stddef.h>
#include <stdint.h>

static inline uint64_t fnv(uint64_t h, const void *data, size_t len)
{
    const unsigned char *p = (const unsigned char *)data;
    for (size_t k = 0; k < len; ++k) {
        h ^= p[k];
        h *= 1099511628211ull;
    }
    return h;
}

#endif
