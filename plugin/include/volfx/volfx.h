/* volfx.h — the whole plugin ABI (ABI 1.0, VFX_ABI_VERSION 2). A host needs this header and
 * nothing else of ours. docs/abi.md states the rules and keeps the changelog; in short:
 *  - one struct per concept; each begins with `type` (its VFX_TYPE_*, checked by the reader: a
 *    wrong one is refused naming the struct) and `next` (a chain of further typed structs, NULL
 *    for none; an entry whose type the reader does not know is skipped);
 *  - a published struct is never edited: a new field arrives as a new chained struct with its own
 *    type value;
 *  - zero means "default" in every field (sokol style), so `{type}` alone is always valid;
 *    resolve_defaults() tells what a zero resolves to;
 *  - nothing here owns global state: every call goes through a context made by create().
 *
 * Threading: every plugin call is made on the thread where the host's GL context is current.
 * Matrices are column-major float[16] (OpenGL/cglm layout). Depth is window depth in [0,1].
 */
#ifndef VOLFX_VOLFX_H
#define VOLFX_VOLFX_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define VFX_ABI_VERSION 2u
/* The additions within VFX_ABI_VERSION this header describes (1 for ABI 1.1). A plugin tells its
 * own in vfx_plugin_info.abi_minor (docs/abi.md "Extensions an older plugin would misread"). */
#define VFX_ABI_MINOR 1u
#define VFX_ENTRY_SYMBOL "vfx_plugin_entry"
/* The installed library's soname (libvolfx.so.<VFX_ABI_VERSION>): dlopen(VFX_SONAME, ...) finds
 * it through the loader's search path, as the game's --plugin does. */
#define VFX_SONAME "libvolfx.so.2"

/* VFX_EXPORT marks the entry point. The plugin's own build defines VFX_BUILDING_PLUGIN (its
 * meson.build does): the symbol is exported (dllexport, default visibility). A host leaves it
 * undefined: on Windows the declaration is dllimport (linking the DLL's import library), or
 * nothing when it links the static plugin and defines VFX_STATIC; elsewhere it is nothing. */
#if defined(VFX_BUILDING_PLUGIN)
#if defined(_WIN32)
#define VFX_EXPORT __declspec(dllexport)
#else
#define VFX_EXPORT __attribute__((visibility("default")))
#endif
#elif defined(_WIN32) && !defined(VFX_STATIC)
#define VFX_EXPORT __declspec(dllimport)
#else
#define VFX_EXPORT
#endif

typedef enum vfx_result {
    VFX_OK = 0,
    VFX_ERR_INVALID_ARGUMENT = 1, /* a NULL, NaN, out-of-range value or bad count */
    VFX_ERR_ABI = 2,              /* ABI version or struct type mismatch between host and plugin */
    VFX_ERR_GL = 3,               /* GL call, shader compile/link or framebuffer failure */
    VFX_ERR_GL_UNSUPPORTED = 4,   /* missing GL version or extension */
    VFX_ERR_OUT_OF_MEMORY = 5,
    VFX_ERR_IO = 6,               /* file cannot be opened or read */
    VFX_ERR_FORMAT = 7,           /* file read but malformed */
    VFX_ERR_NOT_FOUND = 8,        /* asked-for item absent (also: effect not in this world) */
    VFX_ERR_NUMERIC = 9,          /* NaN/Inf or blow-up that could not be recovered */
    VFX_ERR_UNSUPPORTED = 10,     /* feature not built in or not implemented */
} vfx_result;

/* Returns a static, human-readable name of a result code (never NULL). */
static inline const char *vfx_result_name(vfx_result r)
{
    switch (r) {
    case VFX_OK: return "ok";
    case VFX_ERR_INVALID_ARGUMENT: return "invalid argument";
    case VFX_ERR_ABI: return "ABI mismatch";
    case VFX_ERR_GL: return "GL error";
    case VFX_ERR_GL_UNSUPPORTED: return "GL feature unsupported";
    case VFX_ERR_OUT_OF_MEMORY: return "out of memory";
    case VFX_ERR_IO: return "I/O error";
    case VFX_ERR_FORMAT: return "malformed input";
    case VFX_ERR_NOT_FOUND: return "not found";
    case VFX_ERR_NUMERIC: return "numerical failure";
    case VFX_ERR_UNSUPPORTED: return "unsupported";
    }
    return "unknown result";
}

typedef enum vfx_log_level {
    VFX_LOG_DEBUG = 0,
    VFX_LOG_INFO = 1,
    VFX_LOG_WARN = 2,
    VFX_LOG_ERROR = 3,
} vfx_log_level;

typedef enum vfx_effect_kind {
    VFX_EFFECT_WATER = 0,  /* metaball water ray cast from particles (docs/water.md) */
    VFX_EFFECT_BEAMS = 1,  /* energy beams: closed-form line integrals of their densities (docs/beams.md) */
    VFX_EFFECT_VOLUME = 2, /* translucent tetrahedral volumes by cell projection (docs/tetvol.md) */
    VFX_EFFECT_COUNT = 3,
} vfx_effect_kind;

#define VFX_EFFECT_BIT(k) (1u << (k))

/* ------------------------------------------------------------------------ typed structs */

/* The `type` of every struct that crosses the boundary. Values are never renumbered or reused;
 * a struct added later gets the next free value. 0 is no struct (a zeroed header is refused). */
typedef enum vfx_struct_type {
    VFX_TYPE_NONE = 0,
    VFX_TYPE_CONTEXT_DESC = 1,
    VFX_TYPE_FRAME_VIEW = 2,
    VFX_TYPE_PARTICLE_VIEW = 3,
    VFX_TYPE_WATER_PARAMS = 4,
    VFX_TYPE_BEAM = 5,
    VFX_TYPE_BEAMS_VIEW = 6,
    VFX_TYPE_VOLUME_VIEW = 7,
    VFX_TYPE_STATS = 8,
    VFX_TYPE_LIGHTS = 9,
    VFX_TYPE_PLUGIN_API = 10,
    VFX_TYPE_GL_STATE_DESC = 11,
    VFX_TYPE_IMPACT_EVENTS = 12, /* 1.1: chained into vfx_lights.next */
    VFX_TYPE_FRAME_DEPTH = 13, /* 1.1: chained into vfx_frame_view.next */
    VFX_TYPE_PLUGIN_INFO = 14, /* 1.1: chained into vfx_plugin_api.next */
    VFX_TYPE_WATER_FOAM = 15,  /* 1.1: chained into vfx_water_params.next */
    VFX_TYPE_MAX_ENUM = 0x7fffffff
} vfx_struct_type;

/* The header every typed struct begins with (a reader may walk a `next` chain through it). */
typedef struct vfx_chain {
    vfx_struct_type type;
    const void *next;
} vfx_chain;

/* ---------------------------------------------------------------- data the host hands over */

/* A GL buffer object holding one column of particle data: element i at offset + i * stride
 * (bytes), so one interleaved buffer can hold several columns. The buffer must be a buffer object
 * of the current context, stride a multiple of 4 of at least the element's size, offset a multiple
 * of 4, the last element inside GL_BUFFER_SIZE (refused otherwise, VFX_LOG_ID_GPU_COLUMN). The
 * plugin reads it on the GPU at update (docs/integration.md "Particles in GL buffers"). */
typedef struct vfx_gpu_column {
    uint32_t buffer;  /* GL buffer name; 0 -> not used */
    uint32_t stride;  /* bytes between elements */
    uint64_t offset;  /* bytes to element 0 */
} vfx_gpu_column;

/* One chunk of particles as SoA columns, straight from the host's storage (no copy). The
 * plugin hands the host a zeroed view with `type` set; the host fills it. pos[] is required;
 * the other columns may be NULL. `revision` changes whenever the content changes, so the plugin
 * may skip an upload when it has not. Method TILE honours radius and kernel; the paper method
 * refuses either (docs/water.md). */
typedef struct vfx_particle_view {
    vfx_struct_type type;  /* VFX_TYPE_PARTICLE_VIEW */
    const void *next;
    uint32_t count;
    const float *pos[3];   /* x[], y[], z[] */
    const float *vel[3];   /* optional: velocities; the fast particles show as spray and foam */
    const float *radius;   /* optional: per-particle scale of h (1 = h) */
    /* optional: 6 floats per particle (xx, xy, xz, yy, yz, zz) of a symmetric positive
     * definite matrix G; particle i adds P(|G (x - p_i)|) with P the isotropic kernel of radius
     * h (identity: the isotropic kernel; the ellipsoid's semi-axes are h / the eigenvalues of
     * G). Used instead of the kernels the plugin would compute (vfx_water_params.kernel);
     * radius, when given too, divides G. Each eigenvalue must lie in [1e-3, 1e3]. */
    const float *kernel;
    uint64_t revision;
    /* GPU-resident columns instead of pos / vel / kernel (leave those NULL): gpu_pos 3 floats
     * x y z a particle, gpu_vel 3 floats, gpu_kernel 6 floats as `kernel` (read back once an
     * upload for its checks); buffer 0 -> not used. gpu_vel and gpu_kernel need gpu_pos. */
    vfx_gpu_column gpu_pos, gpu_vel, gpu_kernel;
} vfx_particle_view;

/* Bits of vfx_water_params.features_off: what a game may switch off. */
enum {
    /* no diffuse particles (spray, foam and bubbles; they need the velocity columns): none
     * generated, advected or drawn */
    VFX_WATER_NO_SPRAY = 1u << 14,
    /* no screen-space reflection of the host's colour; the reflected ray sees only the cubemap
     * or the sky */
    VFX_WATER_NO_SSR = 1u << 15,
};

/* Zero means the recommended method (TILE). */
typedef enum vfx_water_method {
    VFX_WATER_METHOD_DEFAULT = 0,   /* the recommended method: TILE */
    VFX_WATER_METHOD_TILE = 3,      /* ours (recommended): per-pixel march over screen-tile
                                       particle lists, no sample cap */
    VFX_WATER_METHOD_PAPER = 4,     /* billboards + blended potentials, the published method
                                       (docs/water-paper.md) */
} vfx_water_method;

/* The kernel each particle adds to the field (vfx_water_params.kernel). */
typedef enum vfx_water_kernel {
    VFX_WATER_KERNEL_DEFAULT = 0,     /* the preset's: anisotropic for TILE (isotropic at preset
                                         low), isotropic for the paper method */
    VFX_WATER_KERNEL_ISOTROPIC = 1,   /* P(|x - p|), every method */
    /* Yu & Turk 2013: an ellipsoid per particle from the weighted covariance of its
     * neighbours, computed on the GPU each frame (docs/water.md "Anisotropic kernels"); flat
     * water is flat and thin sheets stay sheets. Method TILE only (the paper method refuses it). */
    VFX_WATER_KERNEL_ANISOTROPIC = 2,
} vfx_water_kernel;

/* Quality presets (vfx_water_params.preset): what each sets and measures is in docs/water.md
 * ("Presets"); a field the host sets explicitly wins over its preset's value. */
typedef enum vfx_water_preset {
    VFX_WATER_PRESET_DEFAULT = 0, /* the recommended one: MEDIUM */
    VFX_WATER_PRESET_LOW = 1,     /* TILE, isotropic kernel, reduced resolution, steps of h/6 */
    VFX_WATER_PRESET_MEDIUM = 2,  /* TILE, anisotropic kernel, reduced resolution, temporal reuse, h/8 */
    VFX_WATER_PRESET_HIGH = 3,    /* MEDIUM at full resolution */
    VFX_WATER_PRESET_ULTRA = 4,   /* HIGH with steps of h/16 and 5 regula falsi steps */
} vfx_water_preset;

/* The water's parameters. The plugin hands the host a zeroed struct with `type` set; zero means
 * default in every field; out-of-range values are refused with the field's name. The diffuse
 * particles (spray, foam and bubbles) follow Ihmsen, Akinci, Akinci & Teschner 2012, "Unified
 * spray, foam and bubbles for particle-based fluids": generated on the GPU from the host's
 * positions and velocities (no velocity columns: none), advected and drawn (docs/water.md
 * "Diffuse particles"); their lengths are in units of h and speeds in units of
 * v_ref = sqrt(|gravity| h). */
typedef struct vfx_water_params {
    vfx_struct_type type;  /* VFX_TYPE_WATER_PARAMS */
    const void *next;
    float h;               /* kernel radius; 0 -> 2 x the particles' spacing (the median nearest-
                              neighbour distance, estimated by the plugin; docs/water.md) */
    float threshold;       /* T in I = sqrt(sum P) - T; 0 -> 0.765625 */
    uint32_t max_samples;  /* the paper method's cap per pixel, <= 4096; 0 -> 64 */
    float step;            /* sample spacing; 0 -> the preset's (h/8) */
    uint32_t refine_iters; /* regula falsi iterations, <= 64; 0 -> the preset's (3) */
    uint32_t pyramid_level;/* the paper method's min/max pyramid level for culling; 0 -> 3 */
    uint32_t features_off; /* VFX_WATER_NO_SPRAY | VFX_WATER_NO_SSR; 0 = everything on */
    uint32_t method;       /* vfx_water_method; 0 -> TILE */
    float color[3];        /* absorption tint; all 0 -> sea water */
    float absorption;      /* per unit length; 0 -> 0.8 / h (clear where thin, tinted a few h deep) */
    float ior;             /* 0 -> 1.333 */
    uint32_t preset;       /* vfx_water_preset */
    /* the kernel; defaults measured on a flat pool (docs/water.md "Anisotropic kernels") */
    uint32_t kernel;               /* vfx_water_kernel */
    float aniso_radius;            /* neighbourhood radius in units of h, 0.5..4; 0 -> 1.5 */
    float aniso_max_stretch;       /* kr: the longest axis over the shortest, 1..64; 0 -> 2 */
    uint32_t aniso_min_neighbours; /* Ne: fewer neighbours -> isotropic, <= 10000; 0 -> 16 */
    float aniso_scale;             /* ks: every axis of a stretched kernel times this, 0.25..4; 0 -> 1.15 */
    /* lambda of the Laplacian smoothing of the centres (centre = (1 - lambda) p + lambda x
     * weighted mean of the neighbours), 0..1; 0 -> none (the default) */
    float aniso_smoothing;
    /* the diffuse particles */
    uint32_t diffuse_max;          /* the pool's cap, 1..4194304; 0 -> 32768 */
    float gravity[3];              /* scene units / s^2 (spray, bubbles, v_ref); 0 -> (0, -9.81, 0) */
    /* potentials' clamp ranges [min, max] (each 0 -> default; min < max):
     * trapped air sum_j |v_ij| (1 - v_ij.x_ij) W_ij in units of v_ref, 0 -> [1.5, 6];
     * wave crest sum_j (1 - n_i.n_j) W_ij over the convex neighbours of a particle moving along
     * its normal, no unit, 0 -> [0.2, 1]; kinetic energy |v|^2 / v_ref^2, 0 -> [0.3, 2] */
    float trapped_air[2], wave_crest[2], energy[2];
    /* particles generated per fluid particle per second at full potential, <= 10000;
     * 0 -> 10 (trapped air) and 25 (wave crest) */
    float rate_trapped_air, rate_wave_crest;
    float lifetime;                /* seconds a foam particle lives (spray and bubbles do not age), <= 60; 0 -> 1.5 */
    float buoyancy;                /* k_b: a bubble's upward acceleration over |gravity|, <= 20; 0 -> 2 */
    float drag;                    /* k_d: a bubble's velocity pulled to the fluid's per second x dt, <= 60; 0 -> 8 */
    /* classification by fluid neighbours within h: fewer than spray_below -> spray, more than
     * bubble_above -> bubble, else foam; 0 -> 6 and 20 (Ihmsen's); spray_below <= bubble_above */
    uint32_t spray_below, bubble_above;
} vfx_water_params;

/* The water's foam layer and its whitewater at beam impacts (ABI 1.1; docs/water.md "Foam
 * layer"), chained into vfx_water_params.next. Absent or zero-filled: every default. The layer is
 * a foam density over the water's horizontal extent (world x and z, texels of `cell` x h): each
 * update the foam particles of the diffuse pool deposit into it, it is carried by the water's
 * depth-averaged velocity, spreads by `diffusion` and fades as exp(-dt / lifetime); the shading
 * draws it where it is dense as a white, lit foam on the surface. */
typedef enum vfx_water_foam_switch {
    VFX_WATER_FOAM_DEFAULT = 0, /* layer: the preset's (on from medium up); impacts: on */
    VFX_WATER_FOAM_ON = 1,
    VFX_WATER_FOAM_OFF = 2,
} vfx_water_foam_switch;

typedef struct vfx_water_foam {
    vfx_struct_type type;  /* VFX_TYPE_WATER_FOAM */
    const void *next;
    uint32_t layer;        /* vfx_water_foam_switch: the foam layer (off: the per-particle foam) */
    uint32_t impacts;      /* vfx_water_foam_switch: spray thrown up where a beam strikes the water */
    float lifetime;        /* seconds the layer's foam takes to fade to 1/e; 0 -> 3 */
    float cell;            /* the layer's texel in units of h; 0 -> 0.5 */
    float diffusion;       /* the layer's spread, h^2 per second; 0 -> 0.5 */
    float deposit;         /* density a foam particle adds per second to its texel area h^2; 0 -> 0.1 */
    float impact_rate;     /* spray drops a second at a beam's impact on the water; 0 -> 600 */
    float impact_speed;    /* their launch speed in units of sqrt(|g| h); 0 -> 4 */
} vfx_water_foam;

/* Support falloff of a beam (docs/beams.md "Smooth support"): the hard one cuts the densities at
 * R; the smooth one multiplies both densities by w(r) = (1 - (r/R)^2)^2, r < R. */
typedef enum vfx_beam_falloff {
    VFX_BEAM_FALLOFF_DEFAULT = 0, /* smooth */
    VFX_BEAM_FALLOFF_SMOOTH = 1,
    VFX_BEAM_FALLOFF_HARD = 2,
} vfx_beam_falloff;

/* How a beam's line integral H becomes light (docs/beams.md "Emission"). */
typedef enum vfx_beam_ramp {
    VFX_BEAM_RAMP_DEFAULT = 0, /* hot */
    /* x = 2^exposure H / c; radiance = intensity x (C + (1 - C) x^2 / (x^2 + 9)): transparent
     * where H -> 0, the beam's colour C, then white-hot and brighter than 1 in the core */
    VFX_BEAM_RAMP_HOT = 1,
    /* the thesis's: the pixel's summed H of such beams, clamped (or smoothly saturated) at c,
     * times their H-weighted colour x intensity x 2^exposure */
    VFX_BEAM_RAMP_THESIS = 2,
} vfx_beam_ramp;

/* The flow's pattern (vfx_beam.flow_kind). */
typedef enum vfx_beam_flow_kind {
    VFX_BEAM_FLOW_NOISE = 0,  /* value noise along the beam */
    VFX_BEAM_FLOW_SPIRAL = 1, /* a helix wound round the axis, moving at flow_speed */
} vfx_beam_flow_kind;

/* One beam, an element of the host's array (each element carries its own `type`). The field is
 * defined exactly in docs/beams.md: head rho_h = a / sqrt(|P-M|^2 + eps^2) inside radius R,
 * trail rho_t = b / sqrt(r^2 + eps^2) around the segment M..M+L*D inside radius R. The attack's
 * anatomy (docs/beams.md "Anatomy of an attack"; every field 0 -> none): the orb and the head
 * are sphere pieces of the same closed form; the body's radius R(u) varies along u = (P - M).D as
 * R (1 - taper u / L) (1 + surge_amount bump(u / surge_wavelength + phase)),
 * bump(x) = ((1 + cos 2 pi x) / 2)^3, phase = surge_speed time / surge_wavelength (surges travel
 * from the source M + L D towards the head M); straight beams only (a polyline ignores taper and
 * surges). */
typedef struct vfx_beam {
    vfx_struct_type type;  /* VFX_TYPE_BEAM */
    const void *next;
    float head[3];   /* M */
    float length;    /* L >= 0 */
    float dir[3];    /* D, normalised by the plugin; zero vector is refused */
    float radius;    /* R > 0 */
    float a, b;      /* head and trail strengths >= 0 */
    float eps;       /* softening >= 0 */
    float color[4];  /* tint multiplied into the ramp; all 0 -> white */
    uint32_t falloff;      /* vfx_beam_falloff */
    uint32_t ramp;         /* vfx_beam_ramp */
    float intensity;       /* radiance multiplier > 0; 0 -> 1 */
    float exposure;        /* stops applied to H before the ramp (finite; 0 -> none) */
    float flow_amount;     /* 0..1: the ramp's x is scaled by 1 + amount (2 n - 1), n a noise in
                              [0, 1] of the beam coordinate at the ray's nearest approach to the
                              axis, moving at flow_speed; H itself stays exact; 0 -> off */
    float flow_speed;      /* units per second along D (the plugin's update time) */
    float flow_scale;      /* noise wavelength along the beam; 0 -> 2 R */
    uint32_t flow_kind;    /* vfx_beam_flow_kind */
    float flow_twist;      /* spiral: turns per flow wavelength (finite); 0 -> 1 */
    /* A bending beam: joint_count (2..6) joints J0.. from the view's joints[joint_first..];
     * the trail's r is the distance to the polyline, the head is at J0, and head, dir and
     * length above are ignored. 0 -> a straight beam. */
    uint32_t joint_first, joint_count;
    float head_radius;       /* the head sphere's support radius (>= 0); 0 -> R */
    float orb_radius;        /* the charging orb at the source M + L D (>= 0); 0 -> no orb */
    float orb_strength;      /* the orb's density strength (like a, >= 0); 0 -> a */
    float orb_pulse;         /* 0..1: the orb's radius times 1 + orb_pulse sin(2 pi orb_pulse_hz time) */
    float orb_pulse_hz;      /* >= 0 */
    float taper;             /* 0..0.95: the body's radius falls linearly to (1 - taper) R at the source */
    float surge_amount;      /* 0..4: a surge widens the body by up to this fraction of R */
    float surge_wavelength;  /* distance between surges (> 0 when surge_amount > 0); 0 -> 8 R */
    float surge_speed;       /* units per second, source to head (finite) */
    /* > 0: the hue-keeping ramp (docs/beams.md "Colour"): the beam's colour C (brightest channel
     * 1) x intensity x (1 - exp(-x)) in the halo, and white (at most 3 x intensity) only where
     * the ray passes within about core x R of the axis, the head or the orb; 0 -> the hot or
     * thesis ramp; at most 1 */
    float core;
} vfx_beam;

typedef enum vfx_saturation { VFX_SATURATE_CLAMP = 0, VFX_SATURATE_SMOOTH = 1 } vfx_saturation;

/* Bloom of the beams' own light (a downsample/upsample chain), for hosts that have none. */
typedef enum vfx_beams_bloom {
    VFX_BEAMS_BLOOM_DEFAULT = 0, /* on */
    VFX_BEAMS_BLOOM_ON = 1,
    VFX_BEAMS_BLOOM_OFF = 2,
} vfx_beams_bloom;

/* The beams of this update. The plugin hands the host a zeroed view with `type` set; count 0 or
 * VFX_ERR_NOT_FOUND -> no beams pass. */
typedef struct vfx_beams_view {
    vfx_struct_type type;    /* VFX_TYPE_BEAMS_VIEW */
    const void *next;
    uint32_t count;
    uint32_t saturation;     /* vfx_saturation */
    const vfx_beam *beams;   /* count beams, each of type VFX_TYPE_BEAM */
    float saturate_c;        /* H mapped to full intensity; 0 -> 1 */
    float far_distance;      /* integrate to here where no surface; 0 -> camera far plane */
    uint32_t bloom;          /* vfx_beams_bloom */
    uint32_t bloom_levels;   /* 1..8 halvings; 0 -> 5 */
    float bloom_strength;    /* bloom added x this (>= 0); 0 -> 0.6 */
    uint32_t joint_count;    /* xyz triples in joints (bending beams index into them) */
    const float *joints;
} vfx_beams_view;

/* Most entries a transfer function table may have. */
#define VFX_VOLUME_MAX_TRANSFER 1024u

/* How a volume's transfer function is integrated along a ray segment. */
typedef enum vfx_volume_transfer_method {
    VFX_VOLUME_TRANSFER_EXACT = 0,         /* split at the table's breakpoints (default) */
    VFX_VOLUME_TRANSFER_PREINTEGRATED = 1, /* pre-integrated lookup table (faster, approximate) */
} vfx_volume_transfer_method;

/* One tetrahedral volume. The plugin hands the host a zeroed view with `type` set. Points,
 * scalars and the table may change every frame: bump revision when points or scalars change
 * (the table is compared by value). */
typedef struct vfx_volume_view {
    vfx_struct_type type;         /* VFX_TYPE_VOLUME_VIEW */
    const void *next;
    uint32_t point_count, tet_count;
    const float *points;          /* xyz per point */
    const uint32_t *tets;         /* 4 point indices per tetrahedron */
    const float *scalar;          /* one value per point */
    float scalar_min, scalar_max; /* transfer function domain; equal -> data range */
    const float *transfer_rgba;   /* transfer_count RGBA entries over the domain, linear between
                                     entries; alpha is extinction per unit length; NULL -> a
                                     default ramp; at most VFX_VOLUME_MAX_TRANSFER */
    uint32_t transfer_count;
    uint32_t transfer_method;     /* vfx_volume_transfer_method */
    const float *transfer_scalar; /* transfer_count breakpoints in [0,1] of the domain
                                     [scalar_min, scalar_max], strictly increasing; NULL ->
                                     evenly spaced */
    float ert_threshold;          /* opacity that terminates a ray; 0 -> 0.9 */
    uint32_t tiles;               /* D of the DxD termination table; 0 -> 20 */
    uint32_t update_c;            /* table updated every remaining/C cells; 0 -> 100 */
    uint32_t workers;             /* threads; 0 -> number of cores */
    float model[16];              /* model matrix; all zero -> identity */
    uint64_t revision;            /* changes when the mesh or scalars change */
} vfx_volume_view;

/* -------------------------------------------------------------------------- context */

/* Stable ids of the plugin's messages (docs/abi.md "Log ids"): the log callback and last_error
 * give one beside the text, so a host can react to a kind of message without matching text
 * (the text names the field or call and the values; the id names the kind). Every message the
 * plugin logs has an id of its own kind; ids are appended, never renumbered or reused. */
#define VFX_LOG_ID_LIST(X) \
    X(NONE, 0)                /* no message (last_error before any failure) */ \
    X(GENERIC, 1)             /* no longer emitted: every message has a kind of its own */ \
    X(ABI_VERSION, 2)         /* the host passed another ABI version to vfx_plugin_entry */ \
    X(STRUCT_TYPE, 3)         /* a struct's type is not the VFX_TYPE_* its place needs */ \
    X(GPU_PARTICLES_UNSUPPORTED, 4) /* no longer emitted (gpu_kernel is read) */ \
    X(LAYER_TEXTURE_UNSUPPORTED, 5) /* no longer emitted (layer_texture is drawn since ABI 1.0) */ \
    X(PARAM_RANGE, 6)         /* a number outside its documented range (volfx_ranges.h; names the field) */ \
    X(FRAME_VIEW, 7)          /* a frame view field or target refused by the frame gate */ \
    X(OUT_OF_MEMORY, 8)       /* an allocation through the host allocator failed */ \
    X(GL_VERSION, 9)          /* the current context is below desktop GL 4.5 */ \
    X(GL_COMMAND_MISSING, 10) /* gl_get_proc_address found no entry point for a command */ \
    X(GPU_COLUMN, 11)         /* a GL buffer column refused (gpu_pos, gpu_vel, gpu_kernel) */ \
    X(LAYER_TEXTURE, 12)      /* a frame view's layer_texture refused */ \
    X(API_ARGUMENT, 13)       /* an API call's argument NULL or out of range (names the call and it) */ \
    X(CONTEXT_DESC, 14)       /* the context desc lacks gl_get_proc_address or half a callback pair */ \
    X(RESIZE_RANGE, 15)       /* resize outside 1..16384 in a direction */ \
    X(UPDATE_TIME, 16)        /* update's time or dt not finite */ \
    X(HOST_CALLBACK, 17)      /* a host callback (particle_chunk, water_params, beams, volume) failed */ \
    X(EFFECT_NOT_BUILT, 18)   /* an effect this build of the plugin leaves out was asked for */ \
    X(EFFECT_NOT_RENDERED, 19) /* read_raw or a lab read before the effect exists or has drawn */ \
    X(READ_BUFFER_SIZE, 20)   /* read_raw or a lab read given less room than the data */ \
    X(GL_ERROR, 21)           /* a GL command of a pass raised a GL error (names the pass, GL_*) */ \
    X(GPU_OUT_OF_MEMORY, 22)  /* GL could not allocate a buffer or texture (GL_OUT_OF_MEMORY) */ \
    X(GL_NO_CONTEXT, 23)      /* no current GL context on the calling thread */ \
    X(FRAMEBUFFER_INCOMPLETE, 24) /* a framebuffer of the plugin's own targets is incomplete */ \
    X(SHADER_COMPILE, 25)     /* an embedded shader did not compile (the driver's log follows) */ \
    X(PROGRAM_LINK, 26)       /* a program did not link (the driver's log follows) */ \
    X(PROGRAM_LIMIT, 27)      /* the plugin's table of GL programs is full */ \
    X(PROGRAM_CACHE_DIR, 28)  /* set_program_cache: the folder cannot be made or is no folder */ \
    X(PROGRAM_CACHE_UNSAFE, 29) /* warning: the cache folder is writable by every user, not sticky */ \
    X(PROGRAM_CACHE_OFF, 30)  /* info: the driver offers no program binary format; no cache */ \
    X(PROGRAM_CACHE_ENTRY, 31) /* warning: a cached binary refused; the program rebuilt from source */ \
    X(PROGRAM_CACHE_STORE, 32) /* warning: a program binary could not be stored */ \
    X(GL_INFO, 33)            /* debug: the GL context's version and profile, commands resolved */ \
    X(EFFECT_CREATED, 34)     /* debug: an effect made (its data appeared in the world) */ \
    X(EFFECT_DESTROYED, 35)   /* debug: an effect freed (its data left the world) */ \
    X(EFFECT_ORDER, 36)       /* an effect's render ran without its prepare step (a plugin defect) */ \
    X(BEAM_FIELD, 37)         /* a vfx_beam field not finite, unknown (falloff, ramp) or degenerate */ \
    X(BEAM_JOINTS, 38)        /* a bending beam's joints refused (range in the view, count, values) */ \
    X(BEAMS_COUNT, 39)        /* more than 2^20 beams, or a count with a NULL array */ \
    X(BEAMS_VIEW_FIELD, 40)   /* a vfx_beams_view value unknown, or a lab struct in its chain */ \
    X(BEAMS_TILE_PAIRS, 41)   /* the beams cover more beam-tile pairs than the binning holds */ \
    X(WATER_PARAM, 42)        /* a vfx_water_params value unknown (method, preset, bits...) or two at odds */ \
    X(WATER_PARTICLE_VALUE, 43) /* a particle's radius or kernel column value refused */ \
    X(WATER_PARTICLE_CHUNK, 44) /* a particle chunk without positions, or changed during the update */ \
    X(WATER_PARTICLE_COUNT, 45) /* more particles than the water's limit of 2^30 */ \
    X(WATER_METHOD, 46)       /* the water's method cannot draw these particles or this kernel */ \
    X(WATER_VIEW_TOO_LARGE, 47) /* the view is too large for the water's targets or tile limit */ \
    X(WATER_UNDECIDED_PIXELS, 48) /* warning: water pixels left undrawn (the march ran out of steps) */ \
    X(VOLUME_MESH, 49)        /* a volume's points or tets refused (missing, index out of range) */ \
    X(VOLUME_SCALAR, 50)      /* a volume's scalar domain not finite, or every scalar NaN */ \
    X(VOLUME_TRANSFER, 51)    /* a volume's transfer function refused */ \
    X(VOLUME_MODEL, 52)       /* a volume's model matrix not finite */ \
    X(VOLUME_EXTRA, 53)       /* warning: the host has several volumes, only the first is drawn */ \
    X(FRAME_DEPTH, 54)        /* a vfx_frame_depth refused, or a proj its depth_convention cannot convert */

typedef enum vfx_log_id {
#define VFX_LOG_ID_ENUM_(name, value) VFX_LOG_ID_##name = value,
    VFX_LOG_ID_LIST(VFX_LOG_ID_ENUM_)
#undef VFX_LOG_ID_ENUM_
    VFX_LOG_ID_MAX_ENUM = 0x7fffffff
} vfx_log_id;

/* The id's name without the prefix ("WATER_PARAM"), or NULL for a value not in this header's
 * list (a newer plugin's id: print the number). Header-only: no ABI entry. */
static inline const char *vfx_log_id_name(vfx_log_id id)
{
    switch (id) {
#define VFX_LOG_ID_NAME_(name, value) case VFX_LOG_ID_##name: return #name;
    VFX_LOG_ID_LIST(VFX_LOG_ID_NAME_)
#undef VFX_LOG_ID_NAME_
    case VFX_LOG_ID_MAX_ENUM: break;
    }
    return NULL;
}

/* What create() needs: the GL loader, the logger and allocator, and the callbacks through which
 * update() pulls the host's data (each hands the host a zeroed struct with `type` set). */
typedef struct vfx_context_desc {
    vfx_struct_type type;  /* VFX_TYPE_CONTEXT_DESC */
    const void *next;
    void *user; /* passed back to every callback */
    /* GL entry points of the current context (eglGetProcAddress/glfwGetProcAddress). */
    void *(*gl_get_proc_address)(void *user, const char *name);
    /* Logger: every message the plugin has for the user comes through here, with its id. */
    void (*log)(void *user, vfx_log_level level, vfx_log_id id, const char *message);
    /* Allocator: NULL alloc/free -> the C library's. alloc returns NULL on failure. */
    void *(*alloc)(void *user, size_t size, size_t align);
    void (*free)(void *user, void *ptr);
    /* Particles (water). count 0 -> no water: the plugin allocates nothing for it. */
    uint32_t (*particle_chunk_count)(void *user);
    vfx_result (*particle_chunk)(void *user, uint32_t index, vfx_particle_view *out);
    /* Water parameters; VFX_ERR_NOT_FOUND -> defaults. NULL callback -> defaults. */
    vfx_result (*water_params)(void *user, vfx_water_params *out);
    /* Beams; count 0 or VFX_ERR_NOT_FOUND -> no beams pass. */
    vfx_result (*beams)(void *user, vfx_beams_view *out);
    /* Tetrahedral volumes. */
    uint32_t (*volume_count)(void *user);
    vfx_result (*volume)(void *user, uint32_t index, vfx_volume_view *out);
} vfx_context_desc;

/* Chained into vfx_context_desc.next: how the plugin treats the host's GL state (docs/integration.md,
 * "GL state contract"). Read at create(). */
typedef struct vfx_gl_state_desc {
    vfx_struct_type type;  /* VFX_TYPE_GL_STATE_DESC */
    const void *next;
    /* Nonzero: the host sets its own state again after every plugin call, so the plugin skips
     * saving and restoring it (it still sets the state its passes depend on, and leaves it). */
    uint32_t skip_restore;
} vfx_gl_state_desc;

/* ------------------------------------------------------------------------ per frame */

#define VFX_MAX_VIEWS 4u

/* One view to draw, written by the host and passed to render() and warm_up(). */
typedef struct vfx_frame_view {
    vfx_struct_type type;   /* VFX_TYPE_FRAME_VIEW */
    const void *next;
    uint32_t framebuffer;   /* GL framebuffer the plugin draws its result into */
    uint32_t color_texture; /* opaque scene colour (RGBA), NOT attached to `framebuffer` */
    uint32_t depth_texture; /* opaque scene depth, NOT attached to `framebuffer`; 0 -> none (far) */
    uint32_t width, height;
    float view[16], proj[16];
    float eye[3];           /* the view matrix's eye (checked against it); (0, 0, 0) -> taken from view */
    float near_plane, far_plane; /* both 0 -> taken from proj */
    float fov_y;            /* radians */
    uint32_t effects;       /* VFX_EFFECT_BIT mask to draw; 0 -> all present */
    double origin[3];       /* world position every position in this frame is relative to
                               (view, eye, particles, beams, volumes): large worlds keep
                               float32 precise near the camera; all 0 -> the world origin */
    uint32_t color_hdr;     /* 1: `framebuffer`'s colour is a float target and effects write
                               linear radiance into it; 0: 8-bit display colour */
    uint32_t environment_cubemap; /* GL cubemap the water reflects; 0 -> a procedural sky */
    /* Each view keeps its own state under its id (the water's temporal history and its
     * size-dependent targets; docs/water.md "Views"), so split screen or a second camera rendered
     * alternately with the first keeps each one's history and sizes. The plugin keeps the
     * VFX_MAX_VIEWS most recently rendered ids; an older one starts afresh. */
    uint32_t view_id;       /* any value */
    /* An effects layer instead of `framebuffer`: a 2D GL_RGBA16F texture of width x height the
     * plugin clears and renders the effects into, premultiplied, for the host to composite as
     * dst = layer.rgb + dst * (1 - layer.a); alpha: water 1, beams 0 (additive), volumes their
     * opacity (docs/integration.md "Effects layer"). 0 -> draw into `framebuffer`. */
    uint32_t layer_texture;
} vfx_frame_view;

/* vfx_frame_depth.depth_convention: the clip control the host's depth was written under. */
typedef enum vfx_depth_convention {
    VFX_DEPTH_STANDARD = 0,    /* glClipControl(.., GL_NEGATIVE_ONE_TO_ONE), GL's default */
    VFX_DEPTH_ZERO_TO_ONE = 1, /* glClipControl(.., GL_ZERO_TO_ONE) (reversed-Z engines use it) */
    VFX_DEPTH_CONVENTION_MAX_ENUM = 0x7fffffff
} vfx_depth_convention;

/* Chained into vfx_frame_view.next: the engine's own depth, when it is not a standard depth
 * texture (docs/integration.md, "The engine's own depth"). A reversed-Z or infinite-far `proj`
 * needs nothing here: the plugin reads it from the projection. Read every render(). */
typedef struct vfx_frame_depth {
    vfx_struct_type type;  /* VFX_TYPE_FRAME_DEPTH */
    const void *next;
    /* A depth renderbuffer of the frame's size, read instead of depth_texture (copied each frame). */
    uint32_t depth_renderbuffer;
    /* Or a framebuffer whose depth attachment (renderbuffer or texture) is read; not both. */
    uint32_t depth_framebuffer;
    /* Nonzero: colour and depth rows are stored top row first, and the output is expected so. */
    uint32_t flip_y;
    /* How the depth and proj were written: VFX_DEPTH_STANDARD or VFX_DEPTH_ZERO_TO_ONE. */
    vfx_depth_convention depth_convention;
} vfx_frame_depth;

typedef struct vfx_stat {
    char name[40];  /* "water.potential.gpu_ms", "beams.pairs_culled", ...: docs/stats.md lists all */
    double value;
} vfx_stat;

/* Room for every pass's timings and every counter of a frame with all effects on. */
#define VFX_STATS_MAX 512
typedef struct vfx_stats {
    vfx_struct_type type;  /* VFX_TYPE_STATS (set by the host) */
    void *next;
    uint32_t count;
    uint32_t dropped;      /* entries the frame made beyond VFX_STATS_MAX (0 normally) */
    vfx_stat entries[VFX_STATS_MAX];
} vfx_stats;

/* ---------------------------------------------------------------------- lights */

/* A light an effect casts on the host's scene (each beam's body, head and impact), for hosts
 * that light their own meshes with it (docs/integration.md "Lights"). Positions are relative to
 * the frame's origin, like every position the host gives. */
typedef enum vfx_light_kind {
    VFX_LIGHT_POINT = 0, /* at p0 (p1 = p0): irradiance I cos(theta) / d^2 */
    VFX_LIGHT_LINE = 1,  /* the segment p0..p1, isotropic, I per unit length: the integral of
                            I cos(theta) / d^2 over the segment */
} vfx_light_kind;

typedef enum vfx_light_source {
    VFX_LIGHT_BEAM_BODY = 0,   /* a beam's trail (one segment of a bending beam) */
    VFX_LIGHT_BEAM_HEAD = 1,   /* a beam's head (its orb) */
    VFX_LIGHT_BEAM_IMPACT = 2, /* where a beam meets the host's depth (read back 1-3 frames late) */
} vfx_light_source;

/* One light (an element the plugin writes into the host's array: no header). */
typedef struct vfx_light {
    uint32_t kind;       /* vfx_light_kind */
    uint32_t source;     /* vfx_light_source */
    uint32_t index;      /* the beam's index in the host's beams view */
    float radius;        /* past this distance from the light its irradiance is below 1/256 of
                            its irradiance at 1 unit: a host may leave it out there */
    float p0[3], p1[3];  /* endpoints (relative to the frame's origin); p1 = p0 for a point */
    float color[3];      /* linear RGB, largest component 1 */
    float intensity;     /* I: radiant intensity (point) or intensity per unit length (line) */
} vfx_light;

/* The host's array for get_lights. */
typedef struct vfx_lights {
    vfx_struct_type type; /* VFX_TYPE_LIGHTS (set by the host) */
    void *next;
    uint32_t capacity;   /* entries at lights */
    uint32_t count;      /* out: entries written (<= capacity) */
    uint32_t total;      /* out: lights the plugin had (more than count when capacity fell short) */
    vfx_light *lights;
} vfx_lights;

/* Where a beam struck the water (ABI 1.1): an impact of a beam's axis on the water's surface, read
 * back with the impact lights (one to three frames late), for a host whose fluid should answer it
 * (the sample game pushes its particles there: docs/simulation.md "Impacts"). */
typedef struct vfx_impact_event {
    float position[3];   /* on the water's surface, relative to the frame's origin */
    float normal[3];     /* the surface's unit normal there, facing the beam */
    float direction[3];  /* the beam's unit direction of travel */
    float energy;        /* the impact's radiant intensity (the I of its VFX_LIGHT_BEAM_IMPACT light) */
    uint32_t beam;       /* the beam's index in the host's beams view */
} vfx_impact_event;

/* Chained into the vfx_lights given to get_lights (lights.next): the plugin fills it too. */
typedef struct vfx_impact_events {
    vfx_struct_type type; /* VFX_TYPE_IMPACT_EVENTS (set by the host) */
    void *next;
    uint32_t capacity;    /* entries at events */
    uint32_t count;       /* out: entries written (<= capacity) */
    uint32_t total;       /* out: impacts on the water the plugin had */
    vfx_impact_event *events;
} vfx_impact_events;

/* ---------------------------------------------------------------------- plugin api */

typedef struct vfx_context vfx_context;

/* The plugin's function table, filled by vfx_plugin_entry (the host sets `type`). */
typedef struct vfx_plugin_api {
    vfx_struct_type type;    /* VFX_TYPE_PLUGIN_API (set by the host) */
    void *next;
    const char *name;        /* "volfx" */
    uint32_t effects_built;  /* VFX_EFFECT_BIT mask compiled into this plugin */
    /* Creates a context on the current GL context; allocates nothing per effect yet. */
    vfx_result (*create)(const vfx_context_desc *desc, vfx_context **out);
    /* Destroys the context and every GL object it made. NULL is allowed. */
    void (*destroy)(vfx_context *ctx);
    /* Reallocates size-dependent targets of the effects that exist. */
    vfx_result (*resize)(vfx_context *ctx, uint32_t width, uint32_t height);
    /* Pulls the host's data (particles, beams, volumes); creates or frees effect state as
     * effects appear or vanish. */
    vfx_result (*update)(vfx_context *ctx, double time, float dt);
    /* Draws every present effect into frame->framebuffer, depth-tested against the host. */
    vfx_result (*render)(vfx_context *ctx, const vfx_frame_view *frame);
    /* Compiles every program the given frame needs, and the driver's variants of them, before
     * the first real frame: after update, it renders `frame` as render() would (into
     * frame->framebuffer, which the host then draws its real first frame over) and waits for the
     * GPU. The effects' state is then that of one rendered frame. */
    vfx_result (*warm_up)(vfx_context *ctx, const vfx_frame_view *frame);
    /* Keeps linked program binaries (GL_ARB_get_program_binary) in the folder `dir`, made if
     * absent: a program found there with this driver (GL_VENDOR, GL_RENDERER, GL_VERSION) and
     * the same source is loaded instead of compiled; a stale, foreign or corrupt file is rebuilt
     * from source and rewritten, never trusted. NULL or "" switches it off (the default). Call it
     * before the frame that first needs a program. */
    vfx_result (*set_program_cache)(vfx_context *ctx, const char *dir);
    /* Copies timings (GPU ms per pass, never stalling) and counters of the last frame. */
    vfx_result (*get_stats)(vfx_context *ctx, vfx_stats *out);
    /* The lights of the effects as of the last update (beams: body and head of this update,
     * impacts as last read back from the GPU), for the host to light its meshes with before it
     * draws them. Call after update. */
    vfx_result (*get_lights)(vfx_context *ctx, vfx_lights *out);
    /* Text of the last error on this context ("" when none); its id into *id_out when not NULL. */
    const char *(*last_error)(vfx_context *ctx, vfx_log_id *id_out);
    /* Reads back an effect's raw quantity of the last render (width*height floats, top row
     * first): water ray distance (-1 = miss), beams H, volume accumulated opacity. */
    vfx_result (*read_raw)(vfx_context *ctx, vfx_effect_kind effect, float *out, size_t count);
    /* Fills every zero field of the typed struct at `inout` (by its `type`: water params, beam,
     * beams view, volume view, frame view; a context desc or particle view has none) with the
     * value zero resolves to, and leaves the fields the host set (docs/abi.md "Resolved
     * defaults"). Values that depend on data (the water's h from the particles' spacing) come
     * from ctx's last update when ctx is given and has one, else stay 0. ctx may be NULL. */
    vfx_result (*resolve_defaults)(vfx_context *ctx, void *inout);
} vfx_plugin_api;

/* Chained by the host into the table it gives vfx_plugin_entry (api.next): the entry fills it
 * with what this plugin reads. A 1.0 plugin skips it and it stays zero. Before chaining an
 * extension whose absence would draw something wrong (vfx_frame_depth), a host checks that the
 * plugin knows it (docs/abi.md "Extensions an older plugin would misread"). */
typedef struct vfx_plugin_info {
    vfx_struct_type type; /* VFX_TYPE_PLUGIN_INFO (set by the host) */
    void *next;
    uint32_t abi_minor;   /* out: VFX_ABI_MINOR of the plugin's build (1: ABI 1.1); 0: a 1.0 plugin */
    uint32_t type_count;  /* out: bits meaningful in known_types (64) */
    uint64_t known_types; /* out: bit t set for every VFX_TYPE_* value t the plugin reads */
} vfx_plugin_info;

/* The one exported symbol. The host passes its ABI version, its context description (optional
 * here: only its log callback is used, to explain a refusal) and the table to fill, whose type
 * it has set. A different ABI version is refused (VFX_ERR_ABI) with a message naming both
 * versions through the host's log callback (an ABI 1 host's too). */
typedef vfx_result (*vfx_plugin_entry_fn)(uint32_t abi_version, const vfx_context_desc *desc,
                                          vfx_plugin_api *out);
VFX_EXPORT vfx_result vfx_plugin_entry(uint32_t abi_version, const vfx_context_desc *desc,
                                       vfx_plugin_api *out);

#ifdef __cplusplus
}
#endif
#endif
