/* volfx.h — the whole plugin ABI. A host needs this header and nothing else of ours.
 *
 * Rules (they keep old hosts and new plugins, or the reverse, safe together):
 *  - every struct that crosses the boundary begins with `size` and `version`; the writer fills
 *    them, the reader refuses a version it does not know and never reads past `size`;
 *  - a published struct is never edited: a new field means a new struct version;
 *  - zero means "default" in every parameter struct (sokol style), so `{0}` plus size/version
 *    is always valid;
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

#define VFX_ABI_VERSION 1u
#define VFX_ENTRY_SYMBOL "vfx_plugin_entry"
/* The installed library's soname (libvolfx.so.<VFX_ABI_VERSION>): dlopen(VFX_SONAME, ...) finds
 * it through the loader's search path, as the game's --plugin does. */
#define VFX_SONAME "libvolfx.so.1"

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
    VFX_ERR_ABI = 2,              /* version or size mismatch between host and plugin */
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

/* ---------------------------------------------------------------- data the host hands over */

/* One chunk of particles as SoA columns, straight from the host's storage (no copy).
 * pos[] is required; the other columns may be NULL. `revision` changes whenever the content
 * changes, so the plugin may skip an upload when it has not. */
#define VFX_PARTICLE_VIEW_VERSION 1u
typedef struct vfx_particle_view {
    uint32_t size, version;
    uint32_t count;
    uint32_t _reserved;
    const float *pos[3];  /* x[], y[], z[] */
    const float *vel[3];  /* optional: velocities; the fast particles show as spray and foam */
    const float *density; /* optional; not read by this version */
    const float *radius;  /* optional: per-particle scale of h (1 = h) */
    uint64_t revision;
} vfx_particle_view;

/* Version 2 of a particle chunk: version 1 as its first member (never edited), then an optional
 * per-particle kernel. The plugin offers one with v1.size = sizeof(vfx_particle_view2) and
 * v1.version = VFX_PARTICLE_VIEW2_VERSION; a host that knows version 2 fills all of it and
 * keeps version 2, a version-1 host writes a vfx_particle_view (version 1: no kernel column).
 * Method TILE honours v1.radius and `kernel`; the other methods refuse either (docs/water.md). */
#define VFX_PARTICLE_VIEW2_VERSION 2u
typedef struct vfx_particle_view2 {
    vfx_particle_view v1;
    /* optional: 6 floats per particle (xx, xy, xz, yy, yz, zz) of a symmetric positive
     * definite matrix G; particle i adds P(|G (x - p_i)|) with P the isotropic kernel of radius
     * h (identity: the isotropic kernel; the ellipsoid's semi-axes are h / the eigenvalues of
     * G). Used instead of the kernels the plugin would compute (vfx_water_params2.kernel);
     * v1.radius, when given too, divides G. Each eigenvalue must lie in [1e-3, 1e3]. */
    const float *kernel;
    uint32_t _reserved[4];
} vfx_particle_view2;

/* Bits of vfx_water_params.disable: each switches one technique of the billboard ray caster (docs/water.md) off, for ablations. */
enum {
    VFX_WATER_NO_BILLBOARD_INIT = 1u << 0, /* technique 1: start every ray at the near plane */
    VFX_WATER_NO_SKIP = 1u << 1,           /* technique 2: fixed steps, no gap jumping */
    VFX_WATER_NO_BLEND = 1u << 2,          /* technique 3: compute-shader sum instead of blending */
    VFX_WATER_NO_PACK4 = 1u << 3,          /* technique 4: one sample per texel, not four */
    VFX_WATER_NO_PYRAMID = 1u << 4,        /* technique 5: no min/max pyramid culling */
    VFX_WATER_NO_REFINE = 1u << 5,         /* technique 6: linear interpolation only */
    VFX_WATER_NO_SHADING = 1u << 6,        /* flat colour: for tests that compare coverage */
    /* PAPER: leave the pixels that spent max_samples undecided (holes), as the seed does,
     * instead of finishing them with TILE's march */
    VFX_WATER_NO_FINISH = 1u << 7,
    /* TILE (ablation): evaluate the field over the tile's whole list at every sample */
    VFX_WATER_NO_LOCAL_LIST = 1u << 8,
    /* TILE (ablation): plain steps, no bound-driven subdivision (features thinner than a step
     * can be missed) */
    VFX_WATER_NO_SUBDIVIDE = 1u << 9,
    /* TILE (ablation): no screen tiles: every pixel reads every particle */
    VFX_WATER_NO_TILES = 1u << 10,
    /* shading (ablation): absorb over the view ray's thickness and look the host colour up at a
     * fixed screen offset, instead of tracing the refracted ray through the water */
    VFX_WATER_NO_REFRACT_TRACE = 1u << 11,
    /* TILE: no temporal reuse (the previous frame's hits, reprojected, as proven starting points) */
    VFX_WATER_NO_TEMPORAL = 1u << 12,
    /* TILE: no reduced-resolution march (one ray per 2x2 block, the rest upsampled where the
     * block agrees and marched where it does not) */
    VFX_WATER_NO_HALF_RES = 1u << 13,
    /* shading: no diffuse particles (spray, foam and bubbles, vfx_water_params4; they need the
     * velocity columns): none generated, advected or drawn */
    VFX_WATER_NO_SPRAY = 1u << 14,
    VFX_WATER_NO_DIFFUSE = VFX_WATER_NO_SPRAY,
    /* shading (ablation): no screen-space reflection of the host's colour; the reflected ray
     * sees only the cubemap or the sky */
    VFX_WATER_NO_SSR = 1u << 15,
};

/* Zero means the recommended method (TILE). The paper method is selected by name (its value was
 * 0 before version 3 of the parameters: zero-filled parameters now mean the recommended look). */
typedef enum vfx_water_method {
    VFX_WATER_METHOD_DEFAULT = 0,   /* the recommended method: TILE */
    VFX_WATER_METHOD_BRUTE = 1,     /* baseline: per-pixel march over all particles (compute) */
    VFX_WATER_METHOD_GRID = 2,      /* baseline: per-pixel march over a uniform grid (compute) */
    VFX_WATER_METHOD_TILE = 3,      /* ours (recommended; scenes default to it): per-pixel march
                                       over screen-tile particle lists, no sample cap */
    VFX_WATER_METHOD_PAPER = 4,     /* billboards + blended potentials, the published method (docs/water.md) */
} vfx_water_method;

#define VFX_WATER_PARAMS_VERSION 1u
typedef struct vfx_water_params {
    uint32_t size, version;
    float h;               /* kernel radius; 0 -> 2 x the particles' spacing (the median nearest-
                              neighbour distance, estimated by the plugin; docs/water.md) */
    float threshold;       /* T in I = sqrt(sum P) - T; 0 -> 0.765625 */
    uint32_t max_samples;  /* cap per pixel, <= 4096 (paper, brute, grid); 0 -> 64 */
    float step;            /* sample spacing; 0 -> the preset's (h/8) */
    uint32_t refine_iters; /* regula falsi iterations, <= 64; 0 -> the preset's (3) */
    uint32_t pyramid_level;/* min/max pyramid level used for culling; 0 -> 3 */
    uint32_t disable;      /* VFX_WATER_NO_* bits; 0 = every technique on */
    uint32_t method;       /* vfx_water_method; 0 -> TILE */
    float color[3];        /* absorption tint; all 0 -> sea water */
    float absorption;      /* per unit length; 0 -> 0.6 */
    float ior;             /* 0 -> 1.333 */
    float _reserved[3];
} vfx_water_params;

/* The kernel each particle adds to the field (vfx_water_params2.kernel). */
typedef enum vfx_water_kernel {
    VFX_WATER_KERNEL_DEFAULT = 0,     /* the preset's: anisotropic for TILE (isotropic at preset
                                         low), isotropic for the other methods */
    VFX_WATER_KERNEL_ISOTROPIC = 1,   /* P(|x - p|), every method */
    /* Yu & Turk 2013: an ellipsoid per particle from the weighted covariance of its
     * neighbours, computed on the GPU each frame (docs/water.md "Anisotropic kernels"); flat
     * water is flat and thin sheets stay sheets. Method TILE only (the others refuse it). */
    VFX_WATER_KERNEL_ANISOTROPIC = 2,
} vfx_water_kernel;

/* Version 2 of the water parameters: version 1 as its first member (never edited), then the
 * kernel. The plugin offers one with v1.size = sizeof(vfx_water_params2) and v1.version =
 * VFX_WATER_PARAMS2_VERSION; a host that knows version 2 fills all of it and keeps version 2,
 * a version-1 host writes a vfx_water_params (version 1: the default kernel). Zero means
 * default in every field; out-of-range values are refused with the field's name. */
#define VFX_WATER_PARAMS2_VERSION 2u
typedef struct vfx_water_params2 {
    vfx_water_params v1;
    uint32_t kernel;               /* vfx_water_kernel */
    /* defaults measured on a flat pool (docs/water.md "Anisotropic kernels") */
    float aniso_radius;            /* neighbourhood radius in units of h, 0.5..4; 0 -> 1.5 */
    float aniso_max_stretch;       /* kr: the longest axis over the shortest, 1..64; 0 -> 2 */
    uint32_t aniso_min_neighbours; /* Ne: fewer neighbours -> isotropic, <= 10000; 0 -> 16 */
    float aniso_scale;             /* ks: every axis of a stretched kernel times this, 0.25..4; 0 -> 1.15 */
    /* lambda of the Laplacian smoothing of the centres (centre = (1 - lambda) p + lambda x
     * weighted mean of the neighbours), 0..1; 0 -> none (the default) */
    float aniso_smoothing;
    uint32_t _reserved[6];
} vfx_water_params2;

/* Quality presets (vfx_water_params3.preset): what each sets and measures is in docs/water.md
 * ("Presets"); a field the host sets explicitly wins over its preset's value. */
typedef enum vfx_water_preset {
    VFX_WATER_PRESET_DEFAULT = 0, /* the recommended one: MEDIUM */
    VFX_WATER_PRESET_LOW = 1,     /* TILE, isotropic kernel, reduced resolution, steps of h/6 */
    VFX_WATER_PRESET_MEDIUM = 2,  /* TILE, anisotropic kernel, reduced resolution, temporal reuse, h/8 */
    VFX_WATER_PRESET_HIGH = 3,    /* MEDIUM at full resolution */
    VFX_WATER_PRESET_ULTRA = 4,   /* HIGH with steps of h/16 and 5 regula falsi steps */
} vfx_water_preset;

/* Version 3 of the water parameters: version 2 as its first member (never edited), then the
 * quality preset. The plugin offers one with v1.size = sizeof(vfx_water_params3) and v1.version =
 * VFX_WATER_PARAMS3_VERSION; a version-1 or version-2 host gets the default preset. Zero means
 * default in every field. */
#define VFX_WATER_PARAMS3_VERSION 3u
typedef struct vfx_water_params3 {
    vfx_water_params2 v2;
    uint32_t preset;               /* vfx_water_preset */
    uint32_t _reserved[7];
} vfx_water_params3;

/* Version 4 of the water parameters: version 3 as its first member (never edited), then the
 * diffuse particles (spray, foam and bubbles) after Ihmsen, Akinci, Akinci & Teschner 2012,
 * "Unified spray, foam and bubbles for particle-based fluids". The plugin generates them on the
 * GPU from the host's positions and velocities (no velocity columns: none), advects them and
 * draws them (docs/water.md "Diffuse particles"). Lengths are in units of h and speeds in units
 * of v_ref = sqrt(|gravity| h), the speed of a gravity wave over h, so a scene in other units
 * sees the same spray; zero means default in every field; out-of-range values are refused with
 * the field's name. The plugin offers one with v1.size = sizeof(vfx_water_params4) and
 * v1.version = VFX_WATER_PARAMS4_VERSION; a host that answers an older version is then offered
 * the older ones in turn (so a host that tests for exactly its version keeps working) and gets
 * these defaults. */
#define VFX_WATER_PARAMS4_VERSION 4u
typedef struct vfx_water_params4 {
    vfx_water_params3 v3;
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
    uint32_t _reserved[8];
} vfx_water_params4;

/* One beam; the field is defined exactly in docs/beams.md:
 * head rho_h = a / sqrt(|P-M|^2 + eps^2) inside radius R, trail rho_t = b / sqrt(r^2 + eps^2)
 * around the segment M..M+L*D inside radius R. */
typedef struct vfx_beam {
    float head[3];   /* M */
    float length;    /* L >= 0 */
    float dir[3];    /* D, normalised by the plugin; zero vector is refused */
    float radius;    /* R > 0 */
    float a, b;      /* head and trail strengths >= 0 */
    float eps;       /* softening >= 0 */
    float _pad;
    float color[4];  /* tint multiplied into the ramp; all 0 -> white */
} vfx_beam;

typedef enum vfx_saturation { VFX_SATURATE_CLAMP = 0, VFX_SATURATE_SMOOTH = 1 } vfx_saturation;

#define VFX_BEAMS_VIEW_VERSION 1u
typedef struct vfx_beams_view {
    uint32_t size, version;
    uint32_t count;
    uint32_t saturation;   /* vfx_saturation */
    const vfx_beam *beams;
    float saturate_c;      /* H mapped to full intensity; 0 -> 1 */
    float far_distance;    /* integrate to here where no surface; 0 -> camera far plane */
    uint32_t method;       /* 0 closed form (default), 1 ray marching (baseline) */
    uint32_t march_samples;/* ray-marching baseline samples; 0 -> 32 */
} vfx_beams_view;

/* Support falloff of a vfx_beam2 (docs/beams.md "Smooth support"): the hard one is version 1's
 * field; the smooth one multiplies both densities by w(r) = (1 - (r/R)^2)^2, r < R. */
typedef enum vfx_beam_falloff {
    VFX_BEAM_FALLOFF_DEFAULT = 0, /* smooth */
    VFX_BEAM_FALLOFF_SMOOTH = 1,
    VFX_BEAM_FALLOFF_HARD = 2,
} vfx_beam_falloff;

/* How a vfx_beam2's line integral H becomes light (docs/beams.md "Emission"). */
typedef enum vfx_beam_ramp {
    VFX_BEAM_RAMP_DEFAULT = 0, /* hot */
    /* x = 2^exposure H / c; radiance = intensity x (C + (1 - C) x^2 / (x^2 + 9)): transparent
     * where H -> 0, the beam's colour C, then white-hot and brighter than 1 in the core */
    VFX_BEAM_RAMP_HOT = 1,
    /* version 1's: the pixel's summed H of such beams, clamped (or smoothly saturated) at c,
     * times their H-weighted colour x intensity x 2^exposure */
    VFX_BEAM_RAMP_THESIS = 2,
} vfx_beam_ramp;

/* Version 2 of a beam: version 1 as its first member (never edited), then the look. */
typedef struct vfx_beam2 {
    vfx_beam v1;
    uint32_t falloff;      /* vfx_beam_falloff */
    uint32_t ramp;         /* vfx_beam_ramp */
    float intensity;       /* radiance multiplier > 0; 0 -> 1 */
    float exposure;        /* stops applied to H before the ramp (finite; 0 -> none) */
    float flow_amount;     /* 0..1: the ramp's x is scaled by 1 + amount (2 n - 1), n a noise in
                              [0, 1] of the beam coordinate at the ray's nearest approach to the
                              axis, moving at flow_speed; H itself stays exact; 0 -> off */
    float flow_speed;      /* units per second along D (the plugin's update time) */
    float flow_scale;      /* noise wavelength along the beam; 0 -> 2 R */
    /* A bending beam: joint_count (2..6) joints J0.. from the view's joints[joint_first..];
     * the trail's r is the distance to the polyline, the head is at J0, and head, dir and
     * length above are ignored. 0 -> the straight beam of v1. */
    uint32_t joint_first, joint_count;
    uint32_t _reserved[7];
} vfx_beam2;

/* Bloom of the beams' own light (a downsample/upsample chain), for hosts that have none. */
typedef enum vfx_beams_bloom {
    VFX_BEAMS_BLOOM_DEFAULT = 0, /* on */
    VFX_BEAMS_BLOOM_ON = 1,
    VFX_BEAMS_BLOOM_OFF = 2,
} vfx_beams_bloom;

/* Version 2 of the beams view: version 1 as its first member. The plugin passes &view.v1 with
 * v1.size = sizeof(vfx_beams_view2) and v1.version = VFX_BEAMS_VIEW2_VERSION; a host that
 * knows version 2 fills all of it and answers version 2, one that knows only version 1 fills
 * v1 and answers version 1 (its beams then get the hard falloff and the thesis ramp). */
#define VFX_BEAMS_VIEW2_VERSION 2u
typedef struct vfx_beams_view2 {
    vfx_beams_view v1;       /* v1.beams is ignored (may be NULL) when beams is set */
    const vfx_beam2 *beams;  /* v1.count beams */
    uint32_t bloom;          /* vfx_beams_bloom */
    uint32_t bloom_levels;   /* 1..8 halvings; 0 -> 5 */
    float bloom_strength;    /* bloom added x this (>= 0); 0 -> 0.6 */
    uint32_t joint_count;    /* xyz triples in joints (bending beams index into them) */
    const float *joints;
    uint32_t _reserved[4];
} vfx_beams_view2;

/* Version 3 of a beam (issue 25, docs/beams.md "Anatomy of an attack"): version 2 as its first
 * member (never edited), then the attack's anatomy. Every field 0 -> version 2's look. The orb
 * and the head are sphere pieces of the same closed form; the body's radius R(u) varies along
 * u = (P - M).D as R (1 - taper u / L) (1 + surge_amount bump(u / surge_wavelength + phase)),
 * bump(x) = ((1 + cos 2 pi x) / 2)^3, phase = surge_speed time / surge_wavelength (surges travel
 * from the source M + L D towards the head M); straight beams only (a polyline ignores taper and
 * surges). */
typedef struct vfx_beam3 {
    vfx_beam2 v2;
    float head_radius;       /* the head sphere's support radius (>= 0); 0 -> R */
    float orb_radius;        /* the charging orb at the source M + L D (>= 0); 0 -> no orb */
    float orb_strength;      /* the orb's density strength (like a, >= 0); 0 -> a */
    float orb_pulse;         /* 0..1: the orb's radius times 1 + orb_pulse sin(2 pi orb_pulse_hz time) */
    float orb_pulse_hz;      /* >= 0 */
    float taper;             /* 0..0.95: the body's radius falls linearly to (1 - taper) R at the source */
    float surge_amount;      /* 0..4: a surge widens the body by up to this fraction of R */
    float surge_wavelength;  /* distance between surges (> 0 when surge_amount > 0); 0 -> 8 R */
    float surge_speed;       /* units per second, source to head (finite) */
    uint32_t flow_kind;      /* vfx_beam_flow_kind */
    float flow_twist;        /* spiral: turns per flow wavelength (finite); 0 -> 1 */
    /* > 0: the hue-keeping ramp (docs/beams.md "Colour"): the beam's colour C (brightest channel
     * 1) x intensity x (1 - exp(-x)) in the halo, and white (at most 3 x intensity) only where
     * the ray passes within about core x R of the axis, the head or the orb; 0 -> the version 2
     * ramp; at most 1 */
    float core;
    uint32_t _reserved[8];
} vfx_beam3;

/* The flow's pattern (vfx_beam3.flow_kind). */
typedef enum vfx_beam_flow_kind {
    VFX_BEAM_FLOW_NOISE = 0,  /* version 2's: value noise along the beam */
    VFX_BEAM_FLOW_SPIRAL = 1, /* a helix wound round the axis, moving at flow_speed */
} vfx_beam_flow_kind;

/* Version 3 of the beams view: version 2 as its first member; the plugin offers it with
 * v1.size = sizeof(vfx_beams_view3), v1.version = VFX_BEAMS_VIEW3_VERSION; a version 3 host
 * sets beams3 (v2.beams and v1.beams are then ignored), an older one answers its version. */
#define VFX_BEAMS_VIEW3_VERSION 3u
typedef struct vfx_beams_view3 {
    vfx_beams_view2 v2;
    const vfx_beam3 *beams3; /* v2.v1.count beams */
    uint32_t _reserved[4];
} vfx_beams_view3;

/* Bits of vfx_volume_view.disable. */
enum {
    VFX_VOLUME_NO_ERT = 1u << 0,   /* no early ray termination at all */
    VFX_VOLUME_NO_SHARE = 1u << 1, /* workers do not share ERT tables */
    VFX_VOLUME_NO_DLB = 1u << 2,   /* no dynamic load balancing */
};

#define VFX_VOLUME_VIEW_VERSION 1u
typedef struct vfx_volume_view {
    uint32_t size, version;
    uint32_t point_count, tet_count;
    const float *points;          /* xyz per point */
    const uint32_t *tets;         /* 4 point indices per tetrahedron */
    const float *scalar;          /* one value per point */
    float scalar_min, scalar_max; /* transfer function domain; equal -> data range */
    const float *transfer_rgba;   /* transfer_count RGBA entries evenly spaced over the domain,
                                     linear between entries; alpha is extinction per unit
                                     length; NULL -> a default ramp; at most
                                     VFX_VOLUME_MAX_TRANSFER */
    uint32_t transfer_count;
    float ert_threshold;          /* opacity that terminates a ray; 0 -> 0.9 */
    uint32_t tiles;               /* D of the DxD termination table; 0 -> 20 */
    uint32_t update_c;            /* table updated every remaining/C cells; 0 -> 100 */
    uint32_t workers;             /* threads; 0 -> number of cores */
    uint32_t disable;             /* VFX_VOLUME_NO_* bits */
    float model[16];              /* model matrix; all zero -> identity */
    uint64_t revision;            /* changes when the mesh or scalars change */
} vfx_volume_view;

/* Most entries a transfer function table may have. */
#define VFX_VOLUME_MAX_TRANSFER 1024u

/* How a volume's transfer function is integrated along a ray segment. */
typedef enum vfx_volume_transfer_method {
    VFX_VOLUME_TRANSFER_EXACT = 0,         /* split at the table's breakpoints (default) */
    VFX_VOLUME_TRANSFER_PREINTEGRATED = 1, /* pre-integrated lookup table (faster, approximate) */
} vfx_volume_transfer_method;

/* Version 2 of the volume view: version 1 as its first member (never edited), then
 * non-uniform transfer-function breakpoints. The plugin offers one with v1.size =
 * sizeof(vfx_volume_view2) and v1.version = VFX_VOLUME_VIEW2_VERSION; a host that knows
 * version 2 fills all of it and keeps version 2, a version-1 host writes a vfx_volume_view
 * (version 1). Points, scalars and the table may change every frame: bump v1.revision when
 * points or scalars change (the table is compared by value). */
#define VFX_VOLUME_VIEW2_VERSION 2u
typedef struct vfx_volume_view2 {
    vfx_volume_view v1;
    const float *transfer_scalar; /* v1.transfer_count breakpoints in [0,1] of the domain
                                     [scalar_min, scalar_max], strictly increasing; NULL ->
                                     evenly spaced (as version 1) */
    uint32_t transfer_method;     /* vfx_volume_transfer_method */
    uint32_t _reserved[5];
} vfx_volume_view2;

/* -------------------------------------------------------------------------- host api */

#define VFX_HOST_API_VERSION 1u
typedef struct vfx_host_api {
    uint32_t size, version;
    void *user; /* passed back to every callback */
    /* GL entry points of the current context (eglGetProcAddress/glfwGetProcAddress). */
    void *(*gl_get_proc_address)(void *user, const char *name);
    /* Logger: every message the plugin has for the user comes through here. */
    void (*log)(void *user, vfx_log_level level, const char *message);
    /* Allocator: NULL alloc/free -> the C library's. alloc returns NULL on failure. */
    void *(*alloc)(void *user, size_t size, size_t align);
    void (*free)(void *user, void *ptr);
    /* Particles (water). count 0 -> no water: the plugin allocates nothing for it. */
    uint32_t (*particle_chunk_count)(void *user);
    /* The plugin offers a vfx_particle_view2 (see there); `out` points at its v1. */
    vfx_result (*particle_chunk)(void *user, uint32_t index, vfx_particle_view *out);
    /* Water parameters; VFX_ERR_NOT_FOUND -> defaults. NULL callback -> defaults. The plugin
     * offers a vfx_water_params2 (see there); `out` points at its v1. */
    vfx_result (*water_params)(void *user, vfx_water_params *out);
    /* Beams; count 0 or VFX_ERR_NOT_FOUND -> no beams pass. */
    vfx_result (*beams)(void *user, vfx_beams_view *out);
    /* Tetrahedral volumes. */
    uint32_t (*volume_count)(void *user);
    vfx_result (*volume)(void *user, uint32_t index, vfx_volume_view *out);
} vfx_host_api;

/* ------------------------------------------------------------------------ per frame */

#define VFX_FRAME_VIEW_VERSION 1u
typedef struct vfx_frame_view {
    uint32_t size, version;
    uint32_t framebuffer;   /* GL framebuffer the plugin draws its result into */
    uint32_t color_texture; /* opaque scene colour (RGBA), NOT attached to `framebuffer` */
    uint32_t depth_texture; /* opaque scene depth, NOT attached to `framebuffer` */
    uint32_t width, height;
    float view[16], proj[16];
    float eye[3];           /* the view matrix's eye (checked against it); (0, 0, 0) -> taken from view */
    float near_plane, far_plane;
    float fov_y;            /* radians */
    uint32_t effects;       /* VFX_EFFECT_BIT mask to draw; 0 -> all present */
    uint32_t _reserved;
} vfx_frame_view;

/* Version 2 of the frame view: version 1 as its first member (never edited), then what large
 * worlds, HDR hosts and reflections need. The host sets v1.size = sizeof(vfx_frame_view2) and
 * v1.version = VFX_FRAME_VIEW2_VERSION and passes &view.v1 to render(); a plugin that knows only
 * version 1 refuses it, this one reads both. */
#define VFX_FRAME_VIEW2_VERSION 2u
typedef struct vfx_frame_view2 {
    vfx_frame_view v1;
    double origin[3];             /* world position every position in this frame is relative to
                                     (view, eye, particles, beams, volumes): large worlds keep
                                     float32 precise near the camera; all 0 -> the world origin */
    uint32_t color_hdr;           /* 1: `framebuffer`'s colour is a float target and effects write
                                     linear radiance into it; 0: 8-bit display colour */
    uint32_t environment_cubemap; /* GL cubemap the water reflects; 0 -> a procedural sky */
    uint32_t _reserved[4];
} vfx_frame_view2;

/* Version 3 of the frame view: version 2 as its first member (never edited), then the view's id.
 * The host sets v1.size = sizeof(vfx_frame_view3) and v1.version = VFX_FRAME_VIEW3_VERSION. Each
 * view keeps its own state under its id (the water's temporal history and its size-dependent
 * targets; docs/water.md "Views"), so split screen or a second camera rendered alternately with
 * the first keeps each one's history and sizes; versions 1 and 2 are view 0. The plugin keeps
 * the VFX_MAX_VIEWS most recently rendered ids; an older one starts afresh. */
#define VFX_FRAME_VIEW3_VERSION 3u
#define VFX_MAX_VIEWS 4u
typedef struct vfx_frame_view3 {
    vfx_frame_view2 v2;
    uint32_t view_id;             /* any value */
    uint32_t _reserved[7];
} vfx_frame_view3;

#define VFX_STATS_MAX 64
typedef struct vfx_stat {
    char name[40];  /* "water.potential.gpu_ms", "beams.pairs_culled", ...: docs/stats.md lists all */
    double value;
} vfx_stat;

#define VFX_STATS_VERSION 1u
typedef struct vfx_stats {
    uint32_t size, version;
    uint32_t count;
    uint32_t _reserved;
    vfx_stat entries[VFX_STATS_MAX];
} vfx_stats;

/* Version 2 of the stats: room for every pass's timings and every counter of a frame with all
 * effects on (version 1 keeps the first VFX_STATS_MAX). The host sets size = sizeof(vfx_stats2)
 * and version = VFX_STATS2_VERSION and passes (vfx_stats *)&stats to get_stats. */
#define VFX_STATS2_MAX 512
#define VFX_STATS2_VERSION 2u
typedef struct vfx_stats2 {
    uint32_t size, version;
    uint32_t count;
    uint32_t dropped;  /* entries the frame made beyond VFX_STATS2_MAX (0 normally) */
    vfx_stat entries[VFX_STATS2_MAX];
} vfx_stats2;

/* ---------------------------------------------------------------------- plugin api */

typedef struct vfx_context vfx_context;

#define VFX_PLUGIN_API_VERSION 1u
typedef struct vfx_plugin_api {
    uint32_t size, version;
    const char *name;        /* "volfx" */
    uint32_t effects_built;  /* VFX_EFFECT_BIT mask compiled into this plugin */
    uint32_t _reserved;
    /* Creates a context on the current GL context; allocates nothing per effect yet. */
    vfx_result (*create)(const vfx_host_api *host, vfx_context **out);
    /* Destroys the context and every GL object it made. NULL is allowed. */
    void (*destroy)(vfx_context *ctx);
    /* Reallocates size-dependent targets of the effects that exist. */
    vfx_result (*resize)(vfx_context *ctx, uint32_t width, uint32_t height);
    /* Pulls the host's data (particles, beams, volumes); creates or frees effect state as
     * effects appear or vanish. */
    vfx_result (*update)(vfx_context *ctx, double time, float dt);
    /* Draws every present effect into frame->framebuffer, depth-tested against the host. */
    vfx_result (*render)(vfx_context *ctx, const vfx_frame_view *frame);
    /* Copies timings (GPU ms per pass, never stalling) and counters of the last frame. */
    vfx_result (*get_stats)(vfx_context *ctx, vfx_stats *out);
    /* Text of the last error on this context ("" when none). */
    const char *(*last_error)(vfx_context *ctx);
    /* Reads back an effect's raw quantity of the last render (width*height floats, top row
     * first): water ray distance (-1 = miss), beams H, volume accumulated opacity. */
    vfx_result (*read_raw)(vfx_context *ctx, vfx_effect_kind effect, float *out, size_t count);
} vfx_plugin_api;

/* Version 2 of the plugin api: version 1 as its first member (never edited), then the calls
 * that take the first-use shader hitch away. A host that knows it sets v1.size =
 * sizeof(vfx_plugin_api2) and passes &api.v1 to vfx_plugin_entry; a plugin that knows it fills
 * all of it and answers v1.version = VFX_PLUGIN_API2_VERSION (an older plugin answers version 1
 * and leaves the rest untouched: check v1.version). */
#define VFX_PLUGIN_API2_VERSION 2u
typedef struct vfx_plugin_api2 {
    vfx_plugin_api v1;
    /* Keeps linked program binaries (GL_ARB_get_program_binary) in the folder `dir`, made if
     * absent: a program found there with this driver (GL_VENDOR, GL_RENDERER, GL_VERSION) and
     * the same source is loaded instead of compiled; a stale, foreign or corrupt file is rebuilt
     * from source and rewritten, never trusted. NULL or "" switches it off (the default). Call it
     * before the frame that first needs a program. */
    vfx_result (*set_program_cache)(vfx_context *ctx, const char *dir);
    /* Compiles every program the given frame needs, and the driver's variants of them, before
     * the first real frame: after update, it renders `frame` as render() would (into
     * frame->framebuffer, which the host then draws its real first frame over) and waits for the
     * GPU. The effects' state is then that of one rendered frame. */
    vfx_result (*warm_up)(vfx_context *ctx, const vfx_frame_view *frame);
    void *_reserved[6];
} vfx_plugin_api2;

/* ---------------------------------------------------------------------- lights */

/* A light an effect casts on the host's scene (issue 25: each beam's body, head and impact), for
 * hosts that light their own meshes with it (docs/integration.md "Lights"). Positions are
 * relative to the frame's origin, like every position the host gives. */
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

#define VFX_LIGHT_VERSION 1u
typedef struct vfx_light {
    uint32_t kind;       /* vfx_light_kind */
    uint32_t source;     /* vfx_light_source */
    uint32_t index;      /* the beam's index in the host's beams view */
    float radius;        /* past this distance from the light its irradiance is below 1/256 of
                            its irradiance at 1 unit: a host may leave it out there */
    float p0[3], p1[3];  /* endpoints (relative to the frame's origin); p1 = p0 for a point */
    float color[3];      /* linear RGB, largest component 1 */
    float intensity;     /* I: radiant intensity (point) or intensity per unit length (line) */
    uint32_t _reserved[4];
} vfx_light;

/* The host's array for get_lights: size = sizeof(vfx_lights), version = VFX_LIGHTS_VERSION,
 * capacity entries of vfx_light (version VFX_LIGHT_VERSION) at lights. */
#define VFX_LIGHTS_VERSION 1u
typedef struct vfx_lights {
    uint32_t size, version;
    uint32_t capacity;   /* entries at lights */
    uint32_t count;      /* out: entries written (<= capacity) */
    uint32_t total;      /* out: lights the plugin had (more than count when capacity fell short) */
    uint32_t _reserved0;
    vfx_light *lights;
    uint32_t _reserved[4];
} vfx_lights;

/* Version 3 of the plugin api: version 2 as its first member (never edited), then the lights.
 * A host that knows it sets v2.v1.size = sizeof(vfx_plugin_api3) and passes &api.v2.v1; a plugin
 * that knows it fills all of it and answers version 3 (an older one answers 1 or 2). */
#define VFX_PLUGIN_API3_VERSION 3u
typedef struct vfx_plugin_api3 {
    vfx_plugin_api2 v2;
    /* The lights of the effects as of the last update (beams: body and head of this update,
     * impacts as last read back from the GPU), for the host to light its meshes with before it
     * draws them. Call after update. */
    vfx_result (*get_lights)(vfx_context *ctx, vfx_lights *out);
    void *_reserved[7];
} vfx_plugin_api3;

/* The one exported symbol. The host passes its ABI version; out->size must be set by the host
 * to sizeof(vfx_plugin_api) it knows (or sizeof(vfx_plugin_api2) or sizeof(vfx_plugin_api3): see there). A different ABI version is refused (VFX_ERR_ABI) with a
 * message naming both versions through host->log. */
typedef vfx_result (*vfx_plugin_entry_fn)(uint32_t abi_version, const vfx_host_api *host,
                                          vfx_plugin_api *out);
VFX_EXPORT vfx_result vfx_plugin_entry(uint32_t abi_version, const vfx_host_api *host,
                                       vfx_plugin_api *out);

#ifdef __cplusplus
}
#endif
#endif
