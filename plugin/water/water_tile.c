/* water_tile.c — method TILE (ours): screen-tile binning of the particles on the GPU and the
 * per-pixel march over the tile lists (shaders/water/tile.comp). The tile lists hold positions
 * (16 bytes an entry) in a buffer of bounded capacity: a tile whose list does not fit reads
 * every particle instead (correct, slower; its pixels are counted, water.tile_overflow_pixels),
 * and the capacity grows to what a recent frame needed (water.tile_entries), up to
 * TILE_MAX_ENTRIES.
 * The prefix sum is the plugin's one GPU scan (gpu/scan.h). */
#include <math.h>
#include <string.h>

#include "gpu/gpu.h"
#include "gpu/pass.h"
#include "gpu/scan.h"
#include "water_tile.h"

/* tiles of 8x8 pixels, or 16, 32 or 64 a side when 8x8 tiles would pass TILE_MAX_TILES
 * (8192x8192 makes 2^20 tiles of 8: one too many for the scan) */
#define TILE_SHIFT_MIN 3
#define TILE_SHIFT_MAX 6
/* tiles + 1 entries must fit the scan */
#define TILE_MAX_TILES (VOLFX_SCAN_MAX - 1u)
/* 256 MiB of entries at most */
#define TILE_MAX_ENTRIES (1u << 24)
/* a particle whose cube covers more tiles than this (512x512 pixels) goes to the global list,
 * scanned by every pixel: one near the eye would otherwise loop over every tile */
#define TILE_GLOBAL_TILES 4096u
/* depth slabs per tile (fewer when tiles * slabs would pass the scan's limit) */
#define TILE_SLABS 32u
/* tile.comp's WaterTile block (std140) */
#define TILE_UBO_BINDING 5u

/* Mirrors tile.comp's WaterTile block (std140): every constant of a TILE frame, uploaded once a
 * frame when the bins are made and read by every tile.comp dispatch of the frame. */
typedef struct tile_block {
    float view_proj[16], inv_view_proj[16];
    float eye[3], h;
    int32_t tiles[2], size[2];
    uint32_t count, cap, global_tiles;
    int32_t tile_shift;
    uint32_t slabs;
    float d0, ds, rbound;
    float threshold, step, window, rho;
    uint32_t refine_iters, has_depth, subdivide, local;
    int32_t sub_depth;
    float half_tol, half_cos;
    uint32_t pad0;
} tile_block;
_Static_assert(sizeof(tile_block) == 240, "tile_block mirrors tile.comp's std140 WaterTile");

/* The loose uniforms that differ between the dispatches of one frame, resolved once per
 * program: tile.comp's march switches. */
enum { LOC_HALF, LOC_TEMPORAL, LOC_REUSE, LOC_COUNT };
#define TILE_PROG_CACHE 8
typedef struct tile_prog_locs {
    GLuint prog;
    GLint loc[LOC_COUNT];
} tile_prog_locs;

struct volfx_water_tile {
    GLuint count, start, entries, globals;
    GLuint entry_ids;    /* ANISO: the particle of each entry (entry_cap of them) */
    uint32_t id_cap;
    uint32_t tile_cap;   /* entries count/start hold */
    uint32_t entry_cap;  /* entries `entries` holds */
    uint32_t global_cap; /* particles `globals` holds */
    uint32_t tiles_x, tiles_y, slabs;
    int shift;           /* tiles of 2^shift pixels a side */
    uint64_t ssbo_max;   /* bytes one storage block may hold (GL_MAX_SHADER_STORAGE_BLOCK_SIZE) */
    float d0, ds;        /* slab k starts at distance d0 + k ds from the eye */
    /* temporal reuse: each pixel's hit point of the frame `hits_frame` (world space), and this
     * frame's reprojected guesses; valid for the next frame only, at the same size and field */
    GLuint hits, guess;
    uint32_t hits_px;    /* pixels the two buffers hold */
    /* reduced resolution: the pixels the upsample could not take (indirect dispatch args first) */
    GLuint remarch;
    uint32_t remarch_px;
    uint32_t hits_w, hits_h;
    int hits_valid;
    uint64_t hits_frame;
    float hits_field[3]; /* h, T, step of those hits */
    float hits_eye[3], hits_fwd[3];
    volfx_ubo ubo;       /* tile_block */
    tile_prog_locs progs[TILE_PROG_CACHE];
    uint32_t nprogs;     /* slots filled; later programs replace them in turn */
};

volfx_water_tile *volfx_water_tile_create(vfx_context *ctx)
{
    volfx_water_tile *t = volfx_alloc(ctx, sizeof *t);
    if (!t)
        return NULL;
    GLint64 block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
    t->ssbo_max = block > 0 ? (uint64_t)block : (1u << 27); /* GL 4.5's minimum is 2^27 */
    if (ctx->debug.water_storage_cap && ctx->debug.water_storage_cap < t->ssbo_max)
        t->ssbo_max = ctx->debug.water_storage_cap;
    if (!volfx_ubo_create(ctx, &t->ubo, sizeof(tile_block), "water.tile")) {
        volfx_water_tile_destroy(ctx, t);
        return NULL;
    }
    return t;
}

void volfx_water_tile_destroy(vfx_context *ctx, volfx_water_tile *t)
{
    if (!t)
        return;
    GLuint b[] = {t->count, t->start, t->entries, t->globals, t->hits, t->guess, t->remarch, t->entry_ids};
    for (int k = 0; k < 8; ++k)
        if (b[k])
            glDeleteBuffers(1, &b[k]);
    volfx_ubo_destroy(&t->ubo);
    volfx_free(ctx, t);
}


/* The loose uniforms' locations of prog, resolved the first time it is seen (a frame uses at
 * most 5 such programs: the cache holds the isotropic and anisotropic sets in turn). */
static const GLint *prog_locs(volfx_water_tile *t, GLuint prog)
{
    for (uint32_t k = 0; k < t->nprogs && k < TILE_PROG_CACHE; ++k)
        if (t->progs[k].prog == prog)
            return t->progs[k].loc;
    static const char *const names[LOC_COUNT] = {"u_half", "u_temporal", "u_reuse"};
    tile_prog_locs *e = &t->progs[t->nprogs++ % TILE_PROG_CACHE];
    e->prog = prog;
    volfx_program_uniforms(prog, names, e->loc, LOC_COUNT);
    return e->loc;
}

/* Fills tile.comp's block for this frame (once, after the bins' sizes are known). */
static void tile_block_upload(const volfx_water_tile *t, const volfx_water_tile_input *in)
{
    const volfx_water_core *p = in->params;
    tile_block b;
    memset(&b, 0, sizeof b);
    memcpy(b.view_proj, in->view_proj, sizeof b.view_proj);
    memcpy(b.inv_view_proj, in->inv_view_proj, sizeof b.inv_view_proj);
    memcpy(b.eye, in->eye, sizeof b.eye);
    b.h = p->h;
    b.tiles[0] = (int32_t)t->tiles_x;
    b.tiles[1] = (int32_t)t->tiles_y;
    b.size[0] = (int32_t)in->width;
    b.size[1] = (int32_t)in->height;
    b.count = in->count;
    b.cap = (p->disable & VFX_WATER_NO_TILES) ? 0u : t->entry_cap;
    b.global_tiles = TILE_GLOBAL_TILES;
    b.tile_shift = t->shift;
    b.slabs = t->slabs;
    b.d0 = t->d0;
    b.ds = t->ds;
    b.rbound = in->kernels ? in->rbound : 0.0f;
    b.threshold = p->threshold;
    b.step = p->step;
    /* a window of 2h holds the spheres one ray meets near its first entry (16 to 30 in dense
     * water at a spacing of h/2); the local list takes 32 */
    b.window = 2.0f * p->h;
    float rho = p->h * (1.0f - p->threshold);
    b.rho = rho > 0 ? rho : 0.0f;
    b.refine_iters = (p->disable & VFX_WATER_NO_REFINE) ? 0u : p->refine_iters;
    b.has_depth = in->has_depth;
    b.subdivide = !(p->disable & VFX_WATER_NO_SUBDIVIDE);
    b.local = !(p->disable & VFX_WATER_NO_LOCAL_LIST);
    /* nodes down to h/128 whatever the step (the step is at most h: water_params.c) */
    int depth = 4;
    while (depth < 7 && p->step > p->h / 8.0f * (float)(1 << (depth - 4)) * 1.0001f)
        ++depth;
    b.sub_depth = depth;
    /* the neighbours' tangent planes agree within a quarter step (the march's own bracket is
     * one step wide before regula falsi) and their normals within 18 degrees */
    b.half_tol = 0.25f * p->step;
    b.half_cos = 0.95f;
    volfx_ubo_update(&t->ubo, &b, sizeof b);
}

static void bind_buffers(const volfx_water_tile *t, const volfx_water_tile_input *in)
{
    for (int k = 0; k < 3; ++k)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, (GLuint)k, in->cols[k]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, t->count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, in->counters);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, t->start);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, t->entries);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 8, t->globals);
    if (in->kernels) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 9, in->kernels);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 10, t->entry_ids);
    }
    if (t->hits) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 12, t->hits);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 13, t->guess);
    }
    if (t->remarch)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 14, t->remarch);
    volfx_ubo_bind(&t->ubo, TILE_UBO_BINDING);
}

/* The tile size (the smallest power of two from 2^TILE_SHIFT_MIN whose tiles number at most
 * the cap) and the depth slabs a tile splits into: *tiles_out screen tiles. */
static vfx_result tile_grid(vfx_context *ctx, volfx_water_tile *t, const volfx_water_tile_input *in,
                            uint32_t max_tiles, uint64_t *tiles_out)
{
    uint64_t tiles = 0;
    for (t->shift = TILE_SHIFT_MIN; t->shift <= TILE_SHIFT_MAX; ++t->shift) {
        uint32_t px = 1u << t->shift;
        t->tiles_x = (in->width + px - 1) / px;
        t->tiles_y = (in->height + px - 1) / px;
        tiles = (uint64_t)t->tiles_x * t->tiles_y;
        if (tiles <= max_tiles)
            break;
    }
    if (tiles > max_tiles) /* 16384^2 at 64x64 tiles is 65,536 of them: only a debug cap gets here */
        return volfx_fail(ctx, VFX_ERR_UNSUPPORTED, VFX_LOG_ID_WATER_VIEW_TOO_LARGE,
                          "water tile: %ux%u pixels make %llu tiles of %ux%u, more than %u",
                          in->width, in->height, (unsigned long long)tiles, 1u << TILE_SHIFT_MAX, 1u << TILE_SHIFT_MAX,
                          max_tiles);
    volfx_stat_set(ctx, "water.tile_pixels", 1u << t->shift);
    t->slabs = TILE_SLABS;
    while (t->slabs > 1 && tiles * t->slabs > max_tiles)
        t->slabs /= 2;
    *tiles_out = tiles;
    return VFX_OK;
}

/* The slabs' depth range: the particles' distances from the eye, from the box (0 when the eye
 * is inside) to its farthest corner, widened for per-particle kernels; *dmin_out the nearest and
 * *hx_out the largest kernel radius (h, or the kernels' bound). */
static void tile_depth_range(volfx_water_tile *t, const volfx_water_tile_input *in, double *dmin_out, double *hx_out)
{
    double dmin2 = 0, dmax2 = 0;
    for (int k = 0; k < 3; ++k) {
        double e = in->eye[k], a = in->lo[k], b = in->hi[k];
        double n = e < a ? a - e : e > b ? e - b : 0, f = fabs(e - a) > fabs(e - b) ? e - a : e - b;
        dmin2 += n * n;
        dmax2 += f * f;
    }
    double dmin = sqrt(dmin2), span = sqrt(dmax2) - dmin;
    /* per-particle kernels are filed by dist - R_i + h (tile.comp), down to dmin - (rbound - h) */
    double hx = in->kernels ? (double)in->rbound : (double)in->params->h;
    if (in->kernels && hx > in->params->h) {
        dmin -= hx - in->params->h;
        span += hx - in->params->h;
    }
    t->d0 = (float)dmin;
    t->ds = (float)(span > 1e-30 ? span / t->slabs * (1.0 + 1e-6) : 1.0);
    *dmin_out = dmin;
    *hx_out = hx;
}

/* The lists' buffers, grown to this frame's tiles and slabs and to the entries it may need
 * (dmin, hx from tile_depth_range); VFX_ERR_OUT_OF_MEMORY when GL cannot make them. */
static vfx_result tile_buffers(vfx_context *ctx, volfx_water_tile *t, const volfx_water_tile_input *in,
                               uint64_t tiles, double dmin, double hx)
{
    /* entries of 16 bytes in one storage block */
    uint64_t max_entries = t->ssbo_max / 16u < TILE_MAX_ENTRIES ? t->ssbo_max / 16u : TILE_MAX_ENTRIES;
    uint32_t nscan = (uint32_t)(tiles * t->slabs) + 1;
    uint32_t need = (nscan + 1023u) & ~1023u;
    if (need > t->tile_cap) {
        if (t->count) glDeleteBuffers(1, &t->count);
        if (t->start) glDeleteBuffers(1, &t->start);
        t->count = volfx_gpu_storage((GLsizeiptr)need * 4, "water.tile_count");
        t->start = volfx_gpu_storage((GLsizeiptr)need * 4, "water.tile_start");
        t->tile_cap = need;
    }
    /* entries: a particle's cube of 2h seen from the box's nearest distance spans at most
     * (2h f / d) / 8 + 2 tiles a side (f the focal length in pixels): the first frame's lists
     * fit unless the box reaches the eye; or what a recent frame needed plus a quarter. A tile
     * that does not fit reads every particle (right, but slow). */
    double fpx = (double)in->focal_px;
    double span_px = dmin > 2.0 * hx ? 2.0 * sqrt(3.0) * hx * fpx / (dmin - hx) : 1e9;
    double per = span_px / (double)(1u << t->shift) + 2.0;
    per = per * per;
    if (per > (double)tiles) per = (double)tiles;
    if (per > TILE_GLOBAL_TILES) per = TILE_GLOBAL_TILES;
    uint64_t want = (uint64_t)fmin((double)in->count * per + 65536.0, (double)max_entries);
    if (in->last_entries) {
        uint64_t w2 = (uint64_t)in->last_entries + in->last_entries / 4u + 1024u;
        if (w2 > want) want = w2;
    }
    if (want > max_entries) want = max_entries;
    if (!t->entries || want > t->entry_cap) {
        if (t->entries) glDeleteBuffers(1, &t->entries);
        t->entries = volfx_gpu_storage((GLsizeiptr)want * 16, "water.tile_entries");
        t->entry_cap = (uint32_t)want;
    }
    if (in->kernels && (!t->entry_ids || t->id_cap < t->entry_cap)) {
        if (t->entry_ids) glDeleteBuffers(1, &t->entry_ids);
        t->entry_ids = volfx_gpu_storage((GLsizeiptr)t->entry_cap * 4, "water.tile_entry_ids");
        t->id_cap = t->entry_cap;
    }
    uint32_t np = in->count ? in->count : 1;
    if (!t->globals || np > t->global_cap) {
        if (t->globals) glDeleteBuffers(1, &t->globals);
        t->globals = volfx_gpu_storage(16 + (GLsizeiptr)np * 16, "water.tile_globals");
        t->global_cap = np;
    }
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY,
                          "water tile: buffers for %llu tiles and %u entries: %s",
                          (unsigned long long)tiles, t->entry_cap, e);
    return VFX_OK;
}

vfx_result volfx_water_tile_bin(vfx_context *ctx, volfx_water_tile *t, const volfx_water_tile_input *in)
{
    uint32_t max_tiles = TILE_MAX_TILES;
    if (ctx->debug.water_max_tiles && ctx->debug.water_max_tiles < max_tiles)
        max_tiles = ctx->debug.water_max_tiles;
    uint64_t tiles = 0;
    double dmin, hx;
    vfx_result r = tile_grid(ctx, t, in, max_tiles, &tiles);
    if (r)
        return r;
    tile_depth_range(t, in, &dmin, &hx);
    if ((r = tile_buffers(ctx, t, in, tiles, dmin, hx)))
        return r;
    uint32_t nscan = (uint32_t)(tiles * t->slabs) + 1;
    uint32_t need = (nscan + 1023u) & ~1023u;
    GLuint count, scatter;
    if (in->kernels) {
        count = volfx_gpu_compute(ctx, "water/tile.comp", "#define MODE_COUNT\n#define ANISO\n");
        scatter = volfx_gpu_compute(ctx, "water/tile.comp", "#define MODE_SCATTER\n#define ANISO\n");
    } else {
        count = volfx_gpu_compute(ctx, "water/tile.comp", "#define MODE_COUNT\n");
        scatter = volfx_gpu_compute(ctx, "water/tile.comp", "#define MODE_SCATTER\n");
    }
    if (!count || !scatter)
        return VFX_ERR_GL;
    tile_block_upload(t, in);
    bind_buffers(t, in);
    GLuint groups = (in->count + 63u) / 64u;
    GLuint gx = groups < 65535u ? groups : 65535u, gy = gx ? (groups + gx - 1) / gx : 0;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.tile_bin", .compute = true});
    glClearNamedBufferSubData(t->count, GL_R32UI, 0, (GLsizeiptr)need * 4, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    glClearNamedBufferSubData(t->globals, GL_R32UI, 0, 16, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    glUseProgram(count);
    if (groups)
        glDispatchCompute(gx, gy, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    r = volfx_gpu_scan(ctx, t->count, t->start, nscan, "water tile bins");
    if (r) {
        volfx_pass_end(ctx);
        return r;
    }
    bind_buffers(t, in);
    /* the counts are spent: the same buffer becomes the per-tile fill cursor of the scatter,
     * and ends holding each tile's count again */
    glClearNamedBufferSubData(t->count, GL_R32UI, 0, (GLsizeiptr)need * 4, GL_RED_INTEGER, GL_UNSIGNED_INT, NULL);
    glUseProgram(scatter);
    if (groups)
        glDispatchCompute(gx, gy, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    volfx_pass_end(ctx);
    volfx_stat_set(ctx, "water.tile_entry_capacity", t->entry_cap);
    return VFX_OK;
}

/* The march over the tile lists: MODE_MARCH writes gradient and back distance for every pixel,
 * MODE_FINISH reads the paper method's state and next step and finishes its sample-cap pixels.
 * The two differ only in the define, the pass name and how images 1 and 2 are bound. */
static vfx_result tile_dispatch(vfx_context *ctx, volfx_water_tile *t, const volfx_water_tile_input *in,
                                const volfx_frame_targets *targets, bool finish, GLuint img1, GLuint img2, int half, bool temporal, bool reuse)
{
    GLuint prog;
    if (finish) /* the paper method's kernel: isotropic */
        prog = volfx_gpu_compute(ctx, "water/tile.comp", "#define MODE_FINISH\n");
    else if (in->kernels) /* stretched kernels overlap more: at a flat pool's surface ~16 supports
                             against ~9 (docs/water-method.md "Anisotropic kernels"); 16 slots sent
                             9,359 pixels of the 3,000-particle pool to the dense fallback and cost
                             1.8x the CPU of 32 */
        prog = volfx_gpu_compute(ctx, "water/tile.comp", half == 2 ? "#define MODE_MARCH\n#define ANISO\n#define LOCAL_K 32\n#define UPSAMPLE_PASS\n"
                                                                   : "#define MODE_MARCH\n#define ANISO\n#define LOCAL_K 32\n");
    else
        prog = volfx_gpu_compute(ctx, "water/tile.comp", half == 2 ? "#define MODE_MARCH\n#define UPSAMPLE_PASS\n" : "#define MODE_MARCH\n");
    if (!prog)
        return VFX_ERR_GL;
    GLenum access = finish ? GL_READ_ONLY : GL_READ_WRITE;
    volfx_pass_begin(ctx, &(volfx_pass_desc){.name = finish      ? "water.finish"
                                                     : half == 2 ? "water.tile_upsample"
                                                     : half == 3 ? "water.tile_remarch" : "water.tile_march",
                                             .compute = true});
    glUseProgram(prog);
    bind_buffers(t, in);
    glBindImageTexture(0, in->dist_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glBindTextureUnit(1, targets->host_depth);
    glBindImageTexture(1, img1, 0, GL_FALSE, 0, access, GL_RGBA32F);
    glBindImageTexture(2, img2, 0, GL_FALSE, 0, access, GL_R32F);
    uint32_t w = in->width, h = in->height;
    if (!finish) {
        glBindImageTexture(0, in->dist_tex, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32F);
        const GLint *loc = prog_locs(t, prog);
        glUniform1i(loc[LOC_HALF], half);
        glUniform1i(loc[LOC_TEMPORAL], temporal);
        glUniform1i(loc[LOC_REUSE], reuse);
        if (half == 1) {
            w = (w + 1) / 2;
            h = (h + 1) / 2;
        }
    }
    if (half == 3) {
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, t->remarch);
        glDispatchComputeIndirect(0);
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
    } else {
        glDispatchCompute((w + 7) / 8, (h + 7) / 8, 1);
    }
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT |
                    GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    volfx_pass_end(ctx);
    const char *e = volfx_gpu_error_string();
    if (e)
        return volfx_fail(ctx, VFX_ERR_GL, VFX_LOG_ID_GL_ERROR,
                          "%s %ux%u: %s", finish ? "water finish" : "water tile march",
                          in->width, in->height, e);
    return VFX_OK;
}

/* A camera cut: the previous frame's hits would be reprojected exactly, but few would land on
 * this frame's surface; the eye moved by more than half its distance to the particles' box
 * centre, or the view turned by more than 30 degrees. */
static bool camera_cut(const volfx_water_tile *t, const volfx_water_tile_input *in, const float fwd[3])
{
    double moved = 0, dist = 0, cosang = 0;
    for (int k = 0; k < 3; ++k) {
        double m = (double)in->eye[k] - t->hits_eye[k], c = 0.5 * ((double)in->lo[k] + in->hi[k]) - t->hits_eye[k];
        moved += m * m;
        dist += c * c;
        cosang += (double)fwd[k] * t->hits_fwd[k];
    }
    return moved > 0.25 * dist || cosang < 0.866;
}

vfx_result volfx_water_tile_march(vfx_context *ctx, volfx_water_tile *t, const volfx_water_tile_input *in,
                                  const volfx_frame_targets *targets, GLuint grad_tex, GLuint back_tex)
{
    const volfx_water_core *p = in->params;
    bool temporal = !(p->disable & VFX_WATER_NO_TEMPORAL);
    bool half = !(p->disable & VFX_WATER_NO_HALF_RES);
    uint32_t px = in->width * in->height;
    /* the hit list (16 bytes a pixel) and the re-march list (4) must each fit one storage block
     * (128 MiB on llvmpipe: 2896^2 and 5792^2 pixels); past that the frame is drawn without
     * temporal reuse or without the reduced resolution (the same surface, more rays) */
    bool limited = false;
    if (temporal && 16u + (uint64_t)px * 16u > t->ssbo_max) temporal = false, limited = true;
    if (half && 16u + (uint64_t)px * 4u > t->ssbo_max) half = false, limited = true;
    volfx_stat_set(ctx, "water.tile_storage_limited", limited);
    if (temporal && (!t->hits || px > t->hits_px)) {
        if (t->hits) glDeleteBuffers(1, &t->hits);
        if (t->guess) glDeleteBuffers(1, &t->guess);
        t->hits = volfx_gpu_storage(16 + (GLsizeiptr)px * 16, "water.tile_hits");
        t->guess = volfx_gpu_storage((GLsizeiptr)px * 4, "water.tile_guess");
        t->hits_px = px;
        t->hits_valid = 0;
        const char *e = volfx_gpu_error_string();
        if (e)
            return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY,
                              "water tile: temporal buffers for %ux%u pixels: %s",
                              in->width, in->height, e);
    }
    /* the view's forward direction: -(third row of the view rotation) */
    const float fwd[3] = {-targets->view[2], -targets->view[6], -targets->view[10]};
    /* last frame's hits hold for this one if they are of the previous water frame (a method or
     * ablation switch in between skips a frame), the same image size and the same field; the
     * particles may have moved (every frame in a game): each guess is only a start, proven or
     * rejected per pixel */
    bool reuse = temporal && t->hits_valid && t->hits_frame + 1 == in->frame_no && t->hits_w == in->width &&
                 t->hits_h == in->height && t->hits_field[0] == p->h && t->hits_field[1] == p->threshold &&
                 t->hits_field[2] == p->step;
    bool cut = reuse && camera_cut(t, in, fwd);
    reuse = reuse && !cut;
    volfx_stat_set(ctx, "water.tile_temporal_valid", reuse);
    volfx_stat_set(ctx, "water.tile_temporal_cut", cut);
    if (reuse) {
        GLuint prog = volfx_gpu_compute(ctx, "water/tile.comp", "#define MODE_REPROJECT\n");
        if (!prog)
            return VFX_ERR_GL;
        volfx_pass_begin(ctx, &(volfx_pass_desc){.name = "water.tile_reproject", .compute = true});
        const uint32_t none = 0xffffffffu;
        glClearNamedBufferSubData(t->guess, GL_R32UI, 0, (GLsizeiptr)px * 4, GL_RED_INTEGER, GL_UNSIGNED_INT, &none);
        glUseProgram(prog);
        bind_buffers(t, in);
        /* one invocation per kept hit point (the march counted the groups) */
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, t->hits);
        glDispatchComputeIndirect(0);
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        volfx_pass_end(ctx);
    }
    if (temporal) {
        /* this frame's hit points replace last frame's: no group, one row, one layer, none */
        const uint32_t args[4] = {0, 1, 1, 0};
        glNamedBufferSubData(t->hits, 0, sizeof args, args);
    }
    if (half && (!t->remarch || px > t->remarch_px)) {
        if (t->remarch) glDeleteBuffers(1, &t->remarch);
        t->remarch = volfx_gpu_storage(16 + (GLsizeiptr)px * 4, "water.tile_remarch");
        t->remarch_px = px;
        const char *e = volfx_gpu_error_string();
        if (e)
            return volfx_fail(ctx, VFX_ERR_OUT_OF_MEMORY, VFX_LOG_ID_GPU_OUT_OF_MEMORY,
                              "water tile: remarch list for %ux%u pixels: %s",
                              in->width, in->height, e);
    }
    vfx_result r = tile_dispatch(ctx, t, in, targets, false, grad_tex, back_tex, half ? 1 : 0, temporal, reuse);
    if (r == VFX_OK && half) {
        /* no group, one row, one layer, no pixel */
        const uint32_t args[4] = {0, 1, 1, 0};
        glNamedBufferSubData(t->remarch, 0, sizeof args, args);
        r = tile_dispatch(ctx, t, in, targets, false, grad_tex, back_tex, 2, temporal, reuse);
        if (r == VFX_OK)
            r = tile_dispatch(ctx, t, in, targets, false, grad_tex, back_tex, 3, temporal, reuse);
    }
    t->hits_valid = temporal && r == VFX_OK;
    t->hits_frame = in->frame_no;
    t->hits_w = in->width;
    t->hits_h = in->height;
    t->hits_field[0] = p->h;
    t->hits_field[1] = p->threshold;
    t->hits_field[2] = p->step;
    memcpy(t->hits_eye, in->eye, sizeof t->hits_eye);
    memcpy(t->hits_fwd, fwd, sizeof t->hits_fwd);
    return r;
}

vfx_result volfx_water_tile_finish(vfx_context *ctx, volfx_water_tile *t, const volfx_water_tile_input *in,
                                   const volfx_frame_targets *targets, GLuint st_tex, GLuint next_tex)
{
    return tile_dispatch(ctx, t, in, targets, true, st_tex, next_tex, 0, false, false);
}
