/* Integer node coordinates as one 64-bit item of an exchange (comm_ops.h)
 * and back: 21 bits an axis, offset by 2^20 (so -2^20 .. 2^20 - 1), x in
 * the highest bits. The grid's halo set-up, the backward-Euler ring and
 * the coarse levels of HOT across ranks send nodes this way. */
#ifndef MPM_NODE_PACK_H
#define MPM_NODE_PACK_H

#include <stdint.h>

#define NODE_PACK_BITS 21
#define NODE_PACK_OFFSET (1 << (NODE_PACK_BITS - 1))
#define NODE_PACK_MASK ((1ull << NODE_PACK_BITS) - 1)

static inline uint64_t node_pack(const int c[3])
{
    return ((uint64_t)(c[0] + NODE_PACK_OFFSET) & NODE_PACK_MASK) << (2 * NODE_PACK_BITS) |
           ((uint64_t)(c[1] + NODE_PACK_OFFSET) & NODE_PACK_MASK) << NODE_PACK_BITS |
           ((uint64_t)(c[2] + NODE_PACK_OFFSET) & NODE_PACK_MASK);
}

static inline void node_unpack(uint64_t k, int c[3])
{
    c[0] = (int)((k >> (2 * NODE_PACK_BITS)) & NODE_PACK_MASK) - NODE_PACK_OFFSET;
    c[1] = (int)((k >> NODE_PACK_BITS) & NODE_PACK_MASK) - NODE_PACK_OFFSET;
    c[2] = (int)(k & NODE_PACK_MASK) - NODE_PACK_OFFSET;
}

#endif
