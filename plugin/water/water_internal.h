/* water_internal.h — the water effect's state, shared by its files: water_effect.c (create,
 * upload, render, counters) and water_paper.c (the seed's billboard method). Nothing outside
 * plugin/water includes it. */
#ifndef VOLFX_WATER_INTERNAL_H
#define VOLFX_WATER_INTERNAL_H

#include "gpu/gl.h"
#include "effect.h"
#include "gpu/pass.h"
#include "water_tile.h"
#include "water_aniso.h"
#include "water_diffuse.h"
#include "water_gather.h"
#include "water_lights.h"
#include "water_foam.h"

/* Counter readback ring: frames the GPU may run behind before a result is dropped. */
#define WATER_COUNTER_RING 3
/* march.comp's 8 (PAPER and the gradient pass), GRID's cells visited and sphere tests,
 * tile.comp's 14 (TILE and the paper method's finishing pass), aniso.comp's 2, shade.frag's
 * SSR hits (26) and diffuse.comp's 4 (27-30: spray, foam, bubbles, generated) */
#define WATER_COUNTERS 32
/* seconds a spray streak spans (its motion blur): two frames at 60 Hz */
#define WATER_SHUTTER_S (1.0f / 30.0f)
/* Particles the effect takes at most: positions are 12 bytes each (12 GiB at the limit) and a
 * particle index must fit the int of gl_InstanceID and of the draw's instance count. */
#define WATER_MAX_PARTICLES (1u << 30)
/* The gradient target accumulates signed terms up to 2/h that partly cancel at the surface:
 * RGBA16F rounds each add to ~5e-4 relative. Measured on the blob test with the brute-force
 * surface (exact to 1e-5 h): mean normal error 0.025 deg in RGBA16F, 0.002 deg in RGBA32F.
 * The pass runs once per frame, not per march iteration, so the wider format costs little. */
#define WATER_GRAD_FORMAT GL_RGBA32F

/* The paper method's per-frame constants: shaders/water/frame.glsl's std140 block WaterFrame
 * (binding 4), uploaded once a frame by volfx_water_frame_upload. */
typedef struct water_frame_block {
    float inv_view_proj[16], view_proj[16];
    float eye[3], h;
    float threshold, step, t_end, near_plane;
    uint32_t max_samples, count, has_depth, pad0;
    int32_t size[2];
    float sizef[2];
} water_frame_block;
_Static_assert(sizeof(water_frame_block) == 192, "water_frame_block mirrors frame.glsl's std140 layout");

/* One chunk of the host's particles as the water reads it (water_effect.c's query_chunk fills it
 * from the particle view): CPU columns, or a GL buffer's columns for the positions and velocities
 * (buffer 0: none). */
typedef struct water_chunk {
    uint32_t count;
    uint64_t revision;
    const float *pos[3], *vel[3], *radius, *kernel;
    volfx_gpu_column gpu_pos, gpu_vel, gpu_kernel;
} water_chunk;

/* One position buffer triple: particles [first, first + count) of the concatenated chunks. */
typedef struct water_group {
    GLuint cols[3];
    uint32_t first, count;
} water_group;

/* The most GPU memory one view's water targets may take: 8192x8192 with TILE (1.5 GiB) fits,
 * 16384x16384 (6 GiB) is refused before anything is allocated (docs/water.md "Views"). */
#define WATER_VIEW_BYTES_MAX (2ull << 30)

/* One view's state (water_view.c): its targets at its size (the paper method's only once one of
 * the other methods drew in it) and its TILE state with the temporal history. */
typedef struct water_view {
    uint32_t id;
    bool live;
    uint64_t used;         /* view_clock when last drawn (the least recent is replaced) */
    uint64_t frames;       /* frames drawn in this view: temporal reuse needs consecutive ones */
    uint32_t width, height;
    GLuint dist, cur, next1, pot, st, br, reft, depth, pyr, grad, back;
    GLuint fbo_dist, fbo_pot, fbo_grad, fbo_back;
    int pyr_levels;
    volfx_water_tile *tile;
} water_view;

typedef struct water_state {
    volfx_water_lights effect_lights; /* the beams' lights on the water (water_lights.h) */
    GLuint cols[3];        /* group 0's columns: the compute paths (brute, NO_BLEND) read only it */
    water_group *groups;   /* position buffers of at most buffer_cap particles each */
    uint32_t group_count;
    uint32_t gl_cap;       /* particles one SSBO binding holds (GL_MAX_SHADER_STORAGE_BLOCK_SIZE) */
    uint32_t buffer_cap;   /* particles per buffer in use: gl_cap or the lower debug knob */
    uint32_t capacity;     /* particles the groups hold */
    uint32_t count;        /* particles uploaded (NaN ones included: the shaders skip them) */
    uint32_t nan_count;
    uint32_t width, height;
    volfx_water_core params;
    volfx_water_kernel_params kp; /* the kernel (vfx_water_params), checked */
    uint32_t preset;       /* vfx_water_params.preset resolved (LOW..ULTRA) */
    uint32_t look;         /* its WATER_LOOK_* bits */
    float auto_h;          /* h from the particles' spacing (0: not measured yet) */
    uint32_t auto_h_count; /* the particle count it was measured at */
    volfx_water_aniso *aniso; /* per-particle kernels (TILE), made when asked for or given */
    void *lab_state;         /* the lab methods' state (ctx->lab's, lab_hooks.h), made on their first frame */
    volfx_water_tile *tile;  /* TILE lists (TILE, and PAPER's finishing pass), made when needed */
    volfx_water_diffuse *diffuse; /* spray, foam and bubbles from the host's velocities */
    volfx_water_diffuse_params dp; /* their parameters (vfx_water_params), checked */
    volfx_water_foam_layer *foam;  /* the foam layer, made when first run */
    volfx_water_foam_params fp;    /* its parameters (vfx_water_foam), resolved */
    float dt;              /* the last update's step, seconds (the diffuse particles') */
    bool diffuse_due;      /* an update since the last diffuse step */
    float lo[3], hi[3];    /* box of the finite particles (GPU chunks: read back late, grown) */
    volfx_water_gather *gather; /* GPU-resident chunks' gather and late box, made on first use */
    uint32_t gpu_count;    /* particles of the last upload that came from GL buffers */
    uint32_t gpu_late;     /* uploads the box of the GPU chunks lagged behind (0: measured now) */
    uint32_t gpu_outside;  /* particles outside the box used, as last read back */
    /* upload skipping: the host's per-chunk revisions of the last upload (0 = untracked: the
     * host gives none, so every frame uploads); data_rev counts uploads, which GRID keys on */
    uint64_t *chunk_rev;
    uint32_t chunk_rev_count;
    uint64_t data_rev;
    int upload_skipped;    /* this frame's update found every revision unchanged */
    uint32_t last_method_drawn; /* method of the last frame: debug_pixel_class reads PAPER's state */
    /* paper pipeline targets */
    GLuint cur, next1, pot, st, br, reft, depth, pyr, fbo_dist, fbo_pot, counters;
    GLuint grad, back, fbo_grad, fbo_back; /* surface gradient and back distance (shading) */
    int pyr_levels;
    /* counters: copied into ring[slot] and fenced each frame, read once the fence signals */
    GLuint ring[WATER_COUNTER_RING];
    GLsync fence[WATER_COUNTER_RING];
    uint64_t ring_frame[WATER_COUNTER_RING];
    uint32_t ring_method[WATER_COUNTER_RING];
    uint64_t frame_no;
    uint32_t last[WATER_COUNTERS];
    uint64_t last_frame;   /* frame whose counters `last` holds */
    uint32_t last_method;
    int have_last;
    uint32_t dropped;      /* counter results overwritten before the GPU finished them */
    uint32_t undecided_warned; /* TILE pixels left undecided were logged (once a context) */
    float view_proj[16];
    GLuint vao; /* empty: billboards are built from gl_VertexID / gl_InstanceID */
    volfx_ubo frame_ubo; /* water_frame_block */
    water_view views[VFX_MAX_VIEWS];
    int active;            /* the view being drawn (its targets are in the fields above), -1 none */
    uint64_t view_clock;
} water_state;

/* Makes `id`'s view the active one (a free or the least recent slot for a new id), its targets at
 * width x height (with the paper method's when `paper`), reallocated only when its own size
 * changed; copies them into s. A size whose targets pass WATER_VIEW_BYTES_MAX fails before
 * allocating (VFX_ERR_UNSUPPORTED, the bytes in the message). */
vfx_result volfx_water_view_begin(vfx_context *ctx, water_state *s, uint32_t id, uint32_t width, uint32_t height,
                                  bool paper);
/* Keeps what the frame made (the TILE state) in the active view; counts the frame when drawn. */
void volfx_water_view_end(water_state *s, bool drawn);
/* Frames the active view has drawn (the temporal history's clock). */
uint64_t volfx_water_view_frames(const water_state *s);
/* Frees every view's targets and TILE state. */
void volfx_water_views_destroy(vfx_context *ctx, water_state *s);
/* An R/RG/RGBA texture of one or more levels with nearest filtering, labelled. */
GLuint volfx_water_make_tex(GLenum fmt, uint32_t w, uint32_t h, int levels, const char *label);
/* Fills and binds the WaterFrame block (binding 4) from this frame's camera, parameters and
 * particle box (s->view_proj already this frame's). */
void volfx_water_frame_upload(water_state *s, const volfx_frame_targets *targets);
/* Binds the host depth at texture unit 1 (the passes that clip at it); none: nothing bound. */
void volfx_water_bind_depth(const volfx_frame_targets *targets);
/* One invocation per pixel in 8x8 groups, then a full barrier. */
void volfx_water_dispatch(const water_state *s);
/* Method PAPER: billboard init, the sample loop and refinement (seed 000, eqs. 1-6). */
vfx_result volfx_water_paper_march(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets);
/* The gradient and back-distance billboard passes that shade PAPER's hits and the lab methods'. */
vfx_result volfx_water_surface_passes(vfx_context *ctx, water_state *s, const volfx_frame_targets *targets);

#endif
