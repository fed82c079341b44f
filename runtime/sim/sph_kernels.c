/* sph_kernels.c — the per-chunk passes: density (cell scan or Verlet walk), forces,
 * integration, displacement; the pair loops take four pairs at a time with SSE2. */
#include "sim/sph_collide.h"
#include "sim/sph_simd.h"
#include "sim/sph_wall.h"

#include <stdlib.h>


/* Grows a per-chunk list buffer to hold `want` entries; false (and nb_oom set) when it cannot. */
static bool grow_list(rt_sph *s, uint32_t **buf, uint32_t *cap, uint32_t want)
{
    if (want <= *cap)
        return true;
    /* 1/8 slack rather than doubling: at 1 M particles the lists are most of the memory, and
     * after the first rebuild their sizes change little */
    uint64_t c64 = (uint64_t)want + want / 8 + 1024;
    uint32_t c = c64 > UINT32_MAX ? UINT32_MAX : (uint32_t)c64;
    uint32_t *nl = realloc(*buf, (size_t)c * sizeof *nl);
    if (!nl) {
        atomic_store(&s->nb_oom, true);
        return false;
    }
    *buf = nl;
    *cap = c;
    return true;
}

/* Everything of the density pass after the neighbour sum: walls, EOS, reductions. */
static inline __attribute__((always_inline)) void
density_tail(rt_sph *s, uint32_t i, float sum, uint32_t nn, float px, float py, float pz,
             sph_chunk_out *o, sph_wall_hit *walls)
{
    const float kp = s->k_poly6, m = s->mass, rho0 = s->p.rest_density;
    const float gam = s->p.gamma, B = s->B, c2_0 = s->c0 * s->c0;
    float rho = m * kp * sum;
    int nw = rt_sph_gather_walls(s, px, py, pz, walls, SPH_MAX_WALLS);
    float inside, extra;
    sph_wall_share(s, walls, nw, NULL, &inside, &extra);
    rho += rho0 * (1.f - inside + extra);
    s->rho[i] = rho;
    /* EOS on the clamped ratio: p >= 0 (no tensile attraction at the free surface) and
     * ratio <= 2 (p <= 127 B) so a collapsed input cannot produce an unbounded force. */
    float ratio = sph_clampf(rho / rho0, 1.f, 2.f);
    float rg1;
    if (gam == 7.f) {
        float q2 = ratio * ratio; /* the default exponent: ratio^6 without a powf call */
        rg1 = q2 * q2 * q2;
    } else {
        rg1 = powf(ratio, gam - 1.f);
    }
    float p = B * (rg1 * ratio - 1.f);
    s->pr[i] = p / (rho * rho);
    float c2 = c2_0 * rg1;
    if (c2 > o->c2_max)
        o->c2_max = c2;
    /* internal (EOS) energy m e(rho), e = int p/rho^2 drho from rho0, with the clamps:
     * what a compressed fluid can turn into motion (tests bound total energy with it) */
    double rr = rho / rho0, rc = rr > 2.0 ? 2.0 : rr;
    if (s->want_energy && rr > 1.0) {
        double e = B / rho0 * ((pow(rc, gam - 1.0) - 1.0) / (gam - 1.0) + 1.0 / rc - 1.0);
        if (rr > 2.0)
            e += B * (pow(2.0, gam) - 1.0) / rho0 * (0.5 - 1.0 / rr);
        o->ie += (double)m * e;
    }
    float err = (rho - rho0) / rho0;
    if (err > o->rho_err_max)
        o->rho_err_max = err;
    if (err > 0.f)
        o->rho_err_sum += err;
    o->pairs += nn;
    if (!isfinite(rho) && o->bad == UINT32_MAX)
        o->bad = i, o->bad_kind = 1, o->bad_value = rho;
}

/* The rows of cells around p (*r) and room in the chunk's lists for all their candidates plus
 * `slack` entries (the Verlet list too when `record`); false when the lists cannot grow. */
static inline __attribute__((always_inline)) bool scan_room(rt_sph *s, uint32_t chunk, float px, float py,
                                                            float pz, const bool record, uint32_t used,
                                                            uint32_t sused, uint32_t slack, sph_ranges *r)
{
    sph_neighbor_ranges(s, px, py, pz, 2, r);
    uint32_t cand = slack;
    for (int q = 0; q < r->count; ++q)
        cand += r->hi[q] - r->lo[q];
    return grow_list(s, &s->cnb[chunk], &s->cnb_cap[chunk], used + cand) &&
           (!record || grow_list(s, &s->snb[chunk], &s->snb_cap[chunk], sused + cand));
}

/* One candidate at a time over the rows of cells in r: appends those within H to L (count *nn)
 * and, when `record`, within H + skin to SL (*ns), self excluded; returns the poly6 sum
 * (H^2 - r^2)^3 of those within H (dropped by a caller that wants the lists only). */
static inline __attribute__((always_inline)) float
scan_ranges(const float *X, const float *Y, const float *Z, const sph_ranges *r, uint32_t i, float px, float py,
            float pz, float H2, float S2, const bool record, uint32_t *L, uint32_t *nn, uint32_t *SL, uint32_t *ns)
{
    float sum = 0.f;
    uint32_t a = *nn, b = *ns;
    for (int q = 0; q < r->count; ++q) {
        for (uint32_t j = r->lo[q]; j < r->hi[q]; ++j) {
            float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
            float r2 = dx * dx + dy * dy + dz * dz;
            if (record && r2 < S2) {
                SL[b] = j;
                b += j != i;
            }
            if (r2 < H2) {
                float t = H2 - r2;
                sum += t * t * t;
                L[a] = j;
                a += j != i;
            }
        }
    }
    *nn = a, *ns = b;
    return sum;
}

/* Closes particle i's lists: offsets and counts, and at a rebuild the Verlet list and the
 * positions it was built at. */
static inline __attribute__((always_inline)) void
lists_close(rt_sph *s, uint32_t i, uint32_t nn, uint32_t ns, const bool record, uint32_t *used, uint32_t *sused,
            sph_chunk_out *o, float px, float py, float pz)
{
    s->nb_start[i] = *used;
    s->nb_count[i] = nn;
    *used += nn;
    if (record) {
        s->sk_start[i] = *sused;
        s->sk_count[i] = ns;
        *sused += ns;
        o->skin_pairs += ns;
        s->x0[i] = px, s->y0[i] = py, s->z0[i] = pz;
    }
}

/* Density by a scan of the 5x5x5 cells, recording the exact list (r < H) for the force pass
 * and, when `record`, the Verlet list (r < H + skin) and the positions it was built at. */
static inline __attribute__((always_inline)) void density_scan(rt_sph *s, uint32_t chunk, const bool record)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float H2 = s->H2, S2 = s->S2;
    /* reductions in a local copy, stored once per chunk: neighbouring chunks' slots share a
     * cache line and run on different threads (false sharing on every particle otherwise) */
    sph_chunk_out acc = s->out[chunk], *o = &acc;
    const float *X = s->x, *Y = s->y, *Z = s->z;
    sph_wall_hit walls[SPH_MAX_WALLS];
    uint32_t used = 0, sused = 0;
    for (uint32_t i = b; i < e; ++i) {
        float px = X[i], py = Y[i], pz = Z[i];
        sph_ranges r;
        if (!scan_room(s, chunk, px, py, pz, record, used, sused, 0, &r)) {
            s->out[chunk] = acc;
            return;
        }
        uint32_t *L = s->cnb[chunk] + used, *SL = record ? s->snb[chunk] + sused : NULL;
        uint32_t nn = 0, ns = 0;
        float sum = scan_ranges(X, Y, Z, &r, i, px, py, pz, H2, S2, record, L, &nn, SL, &ns);
        lists_close(s, i, nn, ns, record, &used, &sused, o, px, py, pz);
        density_tail(s, i, sum, nn, px, py, pz, o, walls);
    }
    if (record)
        s->snb_used[chunk] = sused;
    s->out[chunk] = acc;
}

#if SPH_SSE
/* The lanes of each 4-bit mask, packed to the front, and the mask's bit count. */
static const uint32_t sph_pack_lanes[16][4] __attribute__((aligned(16))) = {
    {0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}, {2, 0, 0, 0}, {0, 2, 0, 0}, {1, 2, 0, 0}, {0, 1, 2, 0},
    {3, 0, 0, 0}, {0, 3, 0, 0}, {1, 3, 0, 0}, {0, 1, 3, 0}, {2, 3, 0, 0}, {0, 2, 3, 0}, {1, 2, 3, 0}, {0, 1, 2, 3}};
static const uint8_t sph_pack_count[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

/* Appends base + the set lanes of `mask` to list[*n..] in lane order: one 16-byte store of which
 * the entries past the new end are scratch (the list needs 3 entries of room beyond it), so the
 * next group's store address waits on one add, not on four dependent ones. */
static inline __attribute__((always_inline)) void sph_append4(uint32_t *list, uint32_t *n, __m128i base, int mask)
{
    __m128i v = _mm_add_epi32(base, _mm_load_si128((const __m128i *)sph_pack_lanes[mask]));
    _mm_storeu_si128((__m128i *)(list + *n), v);
    *n += sph_pack_count[mask];
}

/* Appends the candidates j in [lo, hi) within H (to L, count *nn) and, when `record`, within
 * H + skin (to SL, *ns), self excluded, in increasing j: the lists the scalar scan writes, entry
 * for entry. A row of cells is contiguous, so four candidates are one unaligned load per column;
 * a row's last partial group is the four entries ending at hi with the lanes before `k` masked
 * (reads stay inside [0, n): the caller guarantees n >= 4). Branch-free appends: ~27% of the
 * candidates are within H, an unpredictable branch for the scalar scan. */
static inline __attribute__((always_inline)) void
lists_row_sse(const float *X, const float *Y, const float *Z, uint32_t lo, uint32_t hi, uint32_t i, __m128 vpx,
              __m128 vpy, __m128 vpz, __m128 vH2, __m128 vS2, const bool record, uint32_t *L, uint32_t *nn,
              uint32_t *SL, uint32_t *ns)
{
    const __m128i lane = _mm_setr_epi32(0, 1, 2, 3), vi = _mm_set1_epi32((int)i);
    uint32_t a = *nn, b = *ns;
    for (uint32_t k = lo; k < hi; k += 4) {
        /* the last group overlaps the one before (or starts at 0 for a row ending below 4) */
        uint32_t g = k + 4 <= hi ? k : (hi >= 4 ? hi - 4 : 0);
        __m128 dx = vpx - _mm_loadu_ps(X + g), dy = vpy - _mm_loadu_ps(Y + g), dz = vpz - _mm_loadu_ps(Z + g);
        __m128 r2 = dx * dx + dy * dy + dz * dz;
        const __m128i vg = _mm_set1_epi32((int)g), idx = _mm_add_epi32(vg, lane);
        /* lanes below k were appended by the previous group, lanes from hi are another row's;
         * the self pair is left out (indices < 2^31: the capacity bound is 2^27) */
        __m128i keep = _mm_andnot_si128(_mm_cmpeq_epi32(idx, vi),
                                        _mm_and_si128(_mm_cmpgt_epi32(idx, _mm_set1_epi32((int)k - 1)),
                                                      _mm_cmplt_epi32(idx, _mm_set1_epi32((int)hi))));
        int in = _mm_movemask_ps(_mm_and_ps(_mm_cmplt_ps(r2, vH2), _mm_castsi128_ps(keep)));
        sph_append4(L, &a, vg, in);
        if (record) {
            int sk = _mm_movemask_ps(_mm_and_ps(_mm_cmplt_ps(r2, vS2), _mm_castsi128_ps(keep)));
            sph_append4(SL, &b, vg, sk);
        }
    }
    *nn = a, *ns = b;
}
#endif

/* The lists alone (PBF: every pass after this evaluates its own density) by the 5x5x5 cell scan:
 * the exact list (r < H) and, when `record`, the Verlet list and the positions it was built at.
 * The same lists as density_scan's, four candidates at a time. */
static inline __attribute__((always_inline)) void lists_scan(rt_sph *s, uint32_t chunk, const bool record)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float H2 = s->H2, S2 = s->S2;
    sph_chunk_out acc = s->out[chunk];
    const float *X = s->x, *Y = s->y, *Z = s->z;
    uint32_t used = 0, sused = 0;
    for (uint32_t i = b; i < e; ++i) {
        float px = X[i], py = Y[i], pz = Z[i];
        sph_ranges r;
        /* +3: a group's appends write up to three entries past the last one kept */
        if (!scan_room(s, chunk, px, py, pz, record, used, sused, 3, &r)) {
            s->out[chunk] = acc;
            return;
        }
        uint32_t *L = s->cnb[chunk] + used, *SL = record ? s->snb[chunk] + sused : NULL;
        uint32_t nn = 0, ns = 0;
#if SPH_SSE
        if (s->n >= 4) {
            const __m128 vpx = _mm_set1_ps(px), vpy = _mm_set1_ps(py), vpz = _mm_set1_ps(pz);
            const __m128 vH2 = _mm_set1_ps(H2), vS2 = _mm_set1_ps(S2);
            for (int q = 0; q < r.count; ++q)
                lists_row_sse(X, Y, Z, r.lo[q], r.hi[q], i, vpx, vpy, vpz, vH2, vS2, record, L, &nn, SL, &ns);
        } else
#endif
            (void)scan_ranges(X, Y, Z, &r, i, px, py, pz, H2, S2, record, L, &nn, SL, &ns);
        lists_close(s, i, nn, ns, record, &used, &sused, &acc, px, py, pz);
        acc.pairs += nn;
    }
    if (record)
        s->snb_used[chunk] = sused;
    s->out[chunk] = acc;
}

/* Density by a walk of the Verlet lists (r < H test), writing the exact list for the force
 * pass. Branch-free: ~40% of a list is within H at the default skin of 0.3 H, a coin flip for
 * the predictor (the cell scan's 27% hit rate is why its branch measured cheaper there). */
static inline __attribute__((always_inline)) void density_walk(rt_sph *s, uint32_t chunk, const bool lists_only)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float H2 = s->H2, self = H2 * H2 * H2;
    sph_chunk_out acc = s->out[chunk], *o = &acc;
    const float *X = s->x, *Y = s->y, *Z = s->z;
    sph_wall_hit walls[SPH_MAX_WALLS];
    const uint32_t *SLc = s->snb[chunk];
    uint32_t used = 0;
    for (uint32_t i = b; i < e; ++i) {
        float px = X[i], py = Y[i], pz = Z[i];
        const uint32_t *SL = SLc + s->sk_start[i];
        const uint32_t ns = s->sk_count[i];
        /* the exact list of i is a subset of its Verlet list */
        if (used + ns > s->cnb_cap[chunk] && !grow_list(s, &s->cnb[chunk], &s->cnb_cap[chunk], used + ns)) {
            s->out[chunk] = acc;
            return;
        }
        uint32_t *L = s->cnb[chunk] + used;
        float sum = self;
        uint32_t nn = 0, k = 0;
#if SPH_SSE
        {
            const __m128 vpx = _mm_set1_ps(px), vpy = _mm_set1_ps(py), vpz = _mm_set1_ps(pz);
            const __m128 vH2 = _mm_set1_ps(H2), zero = _mm_setzero_ps();
            __m128 acc = zero;
            for (; k + 4 <= ns; k += 4) {
                uint32_t j0 = SL[k], j1 = SL[k + 1], j2 = SL[k + 2], j3 = SL[k + 3];
                __m128 dx = vpx - _mm_setr_ps(X[j0], X[j1], X[j2], X[j3]);
                __m128 dy = vpy - _mm_setr_ps(Y[j0], Y[j1], Y[j2], Y[j3]);
                __m128 dz = vpz - _mm_setr_ps(Z[j0], Z[j1], Z[j2], Z[j3]);
                __m128 r2 = dx * dx + dy * dy + dz * dz;
                __m128 t = _mm_max_ps(vH2 - r2, zero);
                acc += t * t * t;
                int in = _mm_movemask_ps(_mm_cmplt_ps(r2, vH2));
                L[nn] = j0, nn += (uint32_t)in & 1u;
                L[nn] = j1, nn += ((uint32_t)in >> 1) & 1u;
                L[nn] = j2, nn += ((uint32_t)in >> 2) & 1u;
                L[nn] = j3, nn += ((uint32_t)in >> 3) & 1u;
            }
            sum += sph_hsum(acc);
        }
#endif
        for (; k < ns; ++k) {
            uint32_t j = SL[k];
            float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
            float r2 = dx * dx + dy * dy + dz * dz;
            float t = H2 - r2;
            t = t > 0.f ? t : 0.f;
            sum += t * t * t;
            L[nn] = j;
            nn += r2 < H2;
        }
        s->nb_start[i] = used;
        s->nb_count[i] = nn;
        used += nn;
        o->skin_pairs += ns;
        if (lists_only)
            o->pairs += nn;
        else
            density_tail(s, i, sum, nn, px, py, pz, o, walls);
    }
    s->out[chunk] = acc;
}

void rt_sph_density_chunk(rt_sph *s, uint32_t chunk)
{
    if (s->dens_mode == 2)
        density_walk(s, chunk, false);
    else if (s->dens_mode == 1)
        density_scan(s, chunk, true);
    else
        density_scan(s, chunk, false);
}

void rt_sph_lists_chunk(rt_sph *s, uint32_t chunk)
{
    if (s->dens_mode == 2)
        density_walk(s, chunk, true);
    else if (s->dens_mode == 1)
        lists_scan(s, chunk, true);
    else
        lists_scan(s, chunk, false);
}

/* Squared displacement of every particle since the last rebuild (columns edited by hand). */
void rt_sph_disp_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    float d2 = 0.f;
    for (uint32_t i = b; i < e; ++i) {
        float dx = s->x[i] - s->x0[i], dy = s->y[i] - s->y0[i], dz = s->z[i] - s->z0[i];
        float q = dx * dx + dy * dy + dz * dz;
        if (!(q <= d2))
            d2 = isnan(q) ? INFINITY : q; /* a NaN edit forces a rebuild too */
    }
    s->out[chunk].disp2_max = d2;
}

void rt_sph_coincident_dir(uint32_t a, uint32_t b, float out[3])
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    uint64_t h = ((uint64_t)lo * 0x9E3779B97F4A7C15ull) ^ ((uint64_t)hi * 0xC2B2AE3D27D4EB4Full);
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    float th = (float)((h & 0xFFFF) / 65536.0 * 2.0 * SPH_PI);
    float cz = (float)(((h >> 16) & 0xFFFF) / 65536.0 * 2.0 - 1.0);
    float sz = sqrtf(1.f - cz * cz), sg = a < b ? 1.f : -1.f;
    out[0] = sg * sz * cosf(th), out[1] = sg * sz * sinf(th), out[2] = sg * cz;
}

/* What the pair sums of one chunk read: the particles' columns and the kernel's constants. */
typedef struct sph_force_in {
    const float *X, *Y, *Z, *VX, *VY, *VZ, *R, *P;
    float H, h, eps2, hh, visc;
} sph_force_in;

/* The pair sums of particle i over its nn neighbours L (pressure with Monaghan's viscosity, and
 * the continuity term), before the constant -m ks: out = sum coef w d (3) and sum v.d w. */
static inline void sph_force_pairs(const rt_sph *s, const sph_force_in *f, uint32_t i, const uint32_t *L,
                                   uint32_t nn, float out[4])
{
    const float *X = f->X, *Y = f->Y, *Z = f->Z, *VX = f->VX, *VY = f->VY, *VZ = f->VZ;
    const float *R = f->R, *P = f->P;
    const float H = f->H, h = f->h, eps2 = f->eps2, hh = f->hh, visc = f->visc;
    const float px = X[i], py = Y[i], pz = Z[i], vxi = VX[i], vyi = VY[i], vzi = VZ[i];
    const float pri = P[i], rhoi = R[i];
    /* Per pair, with d = x_i - x_j, r = |d|: grad_i W = -ks (H - r)^2 d / r, so the
     * constant -ks and the mass leave the loop (applied to the sums after it) and the
     * unit vector is never formed; v.u r = v.d in the viscosity term. Fewer live values
     * per pair: the loop had spilled to the stack on every iteration. */
    float sx = 0.f, sy = 0.f, sz = 0.f, sd = 0.f;
    uint32_t coincident = 0, k = 0;
#if SPH_SSE
    /* four pairs at a time: the same operations lane by lane (IEEE, so each pair's
     * terms are the scalar ones), summed per lane and then across */
    {
        const __m128 vpx = _mm_set1_ps(px), vpy = _mm_set1_ps(py), vpz = _mm_set1_ps(pz);
        const __m128 vvx = _mm_set1_ps(vxi), vvy = _mm_set1_ps(vyi), vvz = _mm_set1_ps(vzi);
        const __m128 veps = _mm_set1_ps(eps2), vH = _mm_set1_ps(H), vh = _mm_set1_ps(h);
        const __m128 vhh = _mm_set1_ps(hh), vrho = _mm_set1_ps(rhoi), vpri = _mm_set1_ps(pri);
        const __m128 vvisc = _mm_set1_ps(visc), zero = _mm_setzero_ps();
        __m128 ax4 = zero, ay4 = zero, az4 = zero, ad4 = zero;
        for (; k + 4 <= nn; k += 4) {
            uint32_t j0 = L[k], j1 = L[k + 1], j2 = L[k + 2], j3 = L[k + 3];
#define SPH_G4(A) _mm_setr_ps(A[j0], A[j1], A[j2], A[j3])
            __m128 dx = vpx - SPH_G4(X), dy = vpy - SPH_G4(Y), dz = vpz - SPH_G4(Z);
            __m128 dvx = vvx - SPH_G4(VX), dvy = vvy - SPH_G4(VY), dvz = vvz - SPH_G4(VZ);
            __m128 rj = SPH_G4(R), pj = SPH_G4(P);
#undef SPH_G4
            __m128 r2 = dx * dx + dy * dy + dz * dz;
            __m128 valid = _mm_cmpgt_ps(r2, veps);
            /* lanes with r^2 <= eps2, counted by a nibble table: __builtin_popcount
             * is a libgcc call without -mpopcnt (4% of all instructions) */
            coincident += (0x4332322132212110ull >> (4 * (~_mm_movemask_ps(valid) & 15))) & 15u;
            __m128 rl = _mm_sqrt_ps(r2), hr = vH - rl;
            /* one division for w = (H - r)^2 / r and the viscosity's denominator (the
             * divider is as busy as everything else in this loop); r = 0 lanes get
             * inv = 0, so w = mu = 0 there, not inf or NaN */
            __m128 den = (r2 + vhh) * (vrho + rj);
            __m128 inv = _mm_and_ps(valid, _mm_set1_ps(1.f) / (rl * den));
            __m128 w = hr * hr * den * inv;
            __m128 vdotd = dvx * dx + dvy * dy + dvz * dz;
            __m128 vneg = _mm_min_ps(vdotd, zero);
            __m128 mu = vh * vneg * rl * inv;
            __m128 coef = (vpri + pj - vvisc * mu) * w;
            ax4 += coef * dx, ay4 += coef * dy, az4 += coef * dz;
            ad4 += vdotd * w;
        }
        sx = sph_hsum(ax4), sy = sph_hsum(ay4), sz = sph_hsum(az4), sd = sph_hsum(ad4);
    }
#endif
    for (; k < nn; ++k) {
        uint32_t j = L[k];
        float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
        float r2 = dx * dx + dy * dy + dz * dz;
        float dvx = vxi - VX[j], dvy = vyi - VY[j], dvz = vzi - VZ[j];
        if (r2 > eps2) {
            float rl = sqrtf(r2);
            float hr = H - rl;
            float w = hr * hr / rl; /* |grad W| / (ks r) */
            float vdotd = dvx * dx + dvy * dy + dvz * dz;
            /* Monaghan (1992) artificial viscosity, mu = h v.r/(r^2 + 0.01 h^2),
             * approaching pairs only; branch-free (the sign is a coin flip) */
            float vneg = vdotd < 0.f ? vdotd : 0.f;
            float mu = h * vneg / ((r2 + hh) * (rhoi + R[j]));
            float coef = (pri + P[j] - visc * mu) * w;
            sx += coef * dx, sy += coef * dy, sz += coef * dz;
            sd += vdotd * w;
        } else {
            coincident++;
        }
    }
    /* exactly coincident pairs (r = 0): the deterministic direction u, (H - r)^2 = H^2.
     * In a loop of their own: a call inside the main loop made the compiler keep its
     * array pointers on the stack */
    for (uint32_t k = 0; coincident && k < nn; ++k) {
        uint32_t j = L[k];
        float dx = px - X[j], dy = py - Y[j], dz = pz - Z[j];
        if (!(dx * dx + dy * dy + dz * dz <= eps2))
            continue;
        float u[3];
        rt_sph_coincident_dir(s->id[i], s->id[j], u);
        float coef = (pri + P[j]) * H * H;
        sx += coef * u[0], sy += coef * u[1], sz += coef * u[2];
        sd += ((vxi - VX[j]) * u[0] + (vyi - VY[j]) * u[1] + (vzi - VZ[j]) * u[2]) * H * H;
        coincident--;
    }
    out[0] = sx, out[1] = sy, out[2] = sz, out[3] = sd;
}

void rt_sph_force_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float H = s->H, H2 = s->H2, ks = s->k_spiky, m = s->mass, h = s->h;
    const float alpha = s->p.viscosity, c0 = s->c0;
    const float eps2 = 1e-12f * H2;
    const float hh = 0.01f * h * h, visc = 2.f * alpha * c0, mks = m * ks;
    const float *g = s->p.gravity;
    const float *X = s->x, *Y = s->y, *Z = s->z, *VX = s->vx, *VY = s->vy, *VZ = s->vz;
    const float *R = s->rho, *P = s->pr;
    /* reductions in a local copy, stored once per chunk: neighbouring chunks' slots share a
     * cache line and run on different threads (false sharing on every particle otherwise) */
    sph_chunk_out acc = s->out[chunk], *o = &acc;
    sph_wall_hit walls[SPH_MAX_WALLS];
    const sph_force_in fin = {X, Y, Z, VX, VY, VZ, R, P, H, h, eps2, hh, visc};
    for (uint32_t i = b; i < e; ++i) {
        float px = X[i], py = Y[i], pz = Z[i], vxi = VX[i], vyi = VY[i], vzi = VZ[i];
        float pri = P[i], rhoi = R[i];
        const uint32_t *L = s->cnb[chunk] + s->nb_start[i];
        float sum[4];
        sph_force_pairs(s, &fin, i, L, s->nb_count[i], sum);
        /* a_i = -sum m coef grad W = m ks sum coef w d; d rho_i/dt = sum m v.grad W */
        float ax = mks * sum[0], ay = mks * sum[1], az = mks * sum[2], dr = -mks * sum[3];
        /* the walls (sph_wall.c): mirror image of the missing fluid, division by the fluid's
         * kernel share, wall-law friction */
        {
            float p[3] = {px, py, pz}, v[3] = {vxi, vyi, vzi}, a[3] = {ax, ay, az};
            rt_sph_wall_accel(s, p, v, pri, rhoi, a, walls);
            ax = a[0], ay = a[1], az = a[2];
        }
        ax += g[0], ay += g[1], az += g[2];
        s->ax[i] = ax, s->ay[i] = ay, s->az[i] = az;
        s->drho[i] = dr; /* continuity: d rho_i/dt = sum_j m v_ij . grad_i W_ij */
        float a2 = ax * ax + ay * ay + az * az, v2 = vxi * vxi + vyi * vyi + vzi * vzi;
        if (a2 > o->a2_max)
            o->a2_max = a2;
        if (v2 > o->v2_max)
            o->v2_max = v2;
        if (!isfinite(a2) && o->bad == UINT32_MAX)
            o->bad = i, o->bad_kind = 1, o->bad_value = a2;
    }
    s->out[chunk] = acc;
}

void rt_sph_integrate_chunk(rt_sph *s, uint32_t chunk)
{
    uint32_t b, e;
    sph_chunk_rows(s, chunk, &b, &e);
    const float dt = s->dt_try, margin = 0.25f * s->p.spacing;
    const float vlim2 = s->p.velocity_limit * s->p.velocity_limit, dlim = s->p.density_change_limit;
    const float *lo = s->p.domain_min, *hi = s->p.domain_max;
    const float m = s->mass;
    const float *g = s->p.gravity;
    /* reductions in a local copy, stored once per chunk: neighbouring chunks' slots share a
     * cache line and run on different threads (false sharing on every particle otherwise) */
    sph_chunk_out acc = s->out[chunk], *o = &acc;
    const bool track = s->verlet;
    float disp2 = 0.f;
    for (uint32_t i = b; i < e; ++i) {
        float v[3] = {s->vx[i] + dt * s->ax[i], s->vy[i] + dt * s->ay[i], s->vz[i] + dt * s->az[i]};
        float p[3] = {s->x[i] + dt * v[0], s->y[i] + dt * v[1], s->z[i] + dt * v[2]};
        /* colliders: push back to the margin, remove the velocity into the solid (relative) */
        for (uint32_t c = 0; c < s->ncol; ++c) {
            if (sph_collider_beyond(&s->col[c], p[0], p[1], p[2], margin))
                continue;
            float n[3];
            float d = rt_sph_surface_distance(&s->col[c], p[0], p[1], p[2], n);
            if (d < margin) {
                for (int a = 0; a < 3; ++a)
                    p[a] += (margin - d) * n[a];
                const float *cv = s->col[c].vel;
                float vn = (v[0] - cv[0]) * n[0] + (v[1] - cv[1]) * n[1] + (v[2] - cv[2]) * n[2];
                if (vn < 0.f)
                    for (int a = 0; a < 3; ++a)
                        v[a] -= vn * n[a];
            }
        }
        /* domain box last: nothing leaves it whatever the colliders did */
        for (int a = 0; a < 3; ++a) {
            if (p[a] < lo[a] + margin) {
                p[a] = lo[a] + margin;
                if (v[a] < 0.f)
                    v[a] = 0.f;
            } else if (p[a] > hi[a] - margin) {
                p[a] = hi[a] - margin;
                if (v[a] > 0.f)
                    v[a] = 0.f;
            }
        }
        float v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        float drel = fabsf(dt * s->drho[i] / s->rho[i]);
        if (o->bad == UINT32_MAX) {
            if (!isfinite(v2) || !sph_finite3(p))
                o->bad = i, o->bad_kind = 1, o->bad_value = v2;
            else if (v2 > vlim2)
                o->bad = i, o->bad_kind = 2, o->bad_value = sqrtf(v2);
            else if (!(drel <= dlim))
                o->bad = i, o->bad_kind = 3, o->bad_value = drel;
        }
        s->xn[i] = p[0], s->yn[i] = p[1], s->zn[i] = p[2];
        s->vxn[i] = v[0], s->vyn[i] = v[1], s->vzn[i] = v[2];
        if (track) {
            /* exact per-particle displacement since the rebuild: the rebuild decision is a max
             * over particles, the same whatever the thread count */
            float ex = p[0] - s->x0[i], ey = p[1] - s->y0[i], ez = p[2] - s->z0[i];
            float d2 = ex * ex + ey * ey + ez * ez;
            disp2 = d2 > disp2 ? d2 : disp2;
        }
        o->ke += 0.5 * (double)m * v2;
        o->pe -= (double)m * (g[0] * (p[0] - lo[0]) + g[1] * (p[1] - lo[1]) + g[2] * (p[2] - lo[2]));
    }
    acc.disp2_max = disp2;
    s->out[chunk] = acc;
}
