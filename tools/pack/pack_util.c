// pack_util.c — deterministic random numbers and Morton codes for rouge-pack (see pack.h).
#include "pack/pack.h"

void rs_pack_rng_seed(rs_pack_rng *r, uint64_t seed)
{
    // PCG32 seeding as in the reference implementation (pcg32_srandom_r with stream 54).
    r->state = 0;
    r->inc = (54u << 1) | 1u;
    (void)rs_pack_rng_u32(r);
    r->state += seed;
    (void)rs_pack_rng_u32(r);
}

uint32_t rs_pack_rng_u32(rs_pack_rng *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ull + r->inc;
    uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

double rs_pack_rng_unit(rs_pack_rng *r)
{
    // 53 random bits: every double in [0, 1) on the 2^-53 grid, never 1.
    uint64_t hi = rs_pack_rng_u32(r) >> 5, lo = rs_pack_rng_u32(r) >> 6;
    return (double)(hi * 67108864u + lo) * (1.0 / 9007199254740992.0);
}

static uint64_t spread3(uint32_t v)
{
    uint64_t x = v & 0x1fffffu;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

uint64_t rs_pack_morton3(uint32_t x, uint32_t y, uint32_t z)
{
    return spread3(x) | spread3(y) << 1 | spread3(z) << 2;
}
