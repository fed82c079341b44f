/* scene.h — scene files (JSON, docs/scene-format.md) parsed into a plain C struct. No GL here:
 * the game and the bench turn a rt_scene into meshes, particles, beams and volumes.
 *
 * Every bad input is refused with a vfx_result and a message that names the JSON path of the
 * offending value ("beams[2].radius: must be > 0, got -1"), or the line and column of a syntax
 * error. Unknown keys are not errors: they are reported as warnings through the logger. */
#ifndef RT_SCENE_H
#define RT_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <volfx/volfx.h>

#include "core/log.h"

#define RT_SCENE_FORMAT_VERSION 1
/* camera.eye when the scene gives none (also the origin of a scene without "origin") */
#define RT_SCENE_DEFAULT_EYE 0, 2, 6
#define RT_SCENE_MAX_BYTES (16u << 20)        /* scene files above 16 MiB are refused */
#define RT_SCENE_MAX_MESHES 64
#define RT_SCENE_MAX_BEAMS 256
#define RT_SCENE_MAX_JOINTS 6 /* joints of a bending beam (the plugin's limit) */
#define RT_SCENE_MAX_KEYS 4096                /* keyframes per animated parameter */
#define RT_SCENE_MAX_TRANSFER 256             /* transfer-function control points */
#define RT_SCENE_MAX_PARTICLES (1u << 22)     /* generated or simulated particles (4,194,304) */
#define RT_SCENE_MAX_VOLUME_CELLS 64          /* generated volume: cells per axis (1.5M tets) */
#define RT_SCENE_PATH_MAX 1024

typedef struct rt_scene_camera {
    float eye[3], target[3], up[3];
    float fov_y_deg;
    uint32_t width, height;
    float near_plane, far_plane;
} rt_scene_camera;

typedef struct rt_scene_mesh {
    bool is_box;                        /* a generated box instead of a file */
    char path[RT_SCENE_PATH_MAX];      /* Assimp-readable file, resolved against the scene */
    float box_min[3], box_max[3];
    float model[16];                    /* column-major, from translate/rotate/scale or matrix */
    float color[3];
} rt_scene_mesh;

/* Animated parameters of a beam, in the order of rt_scene_beam.tracks[]. */
typedef enum rt_scene_beam_param {
    RT_BEAM_PARAM_HEAD = 0,   /* 3 values */
    RT_BEAM_PARAM_DIR,        /* 3 */
    RT_BEAM_PARAM_LENGTH,     /* 1 */
    RT_BEAM_PARAM_RADIUS,     /* 1 */
    RT_BEAM_PARAM_A,          /* 1 */
    RT_BEAM_PARAM_B,          /* 1 */
    RT_BEAM_PARAM_EPS,        /* 1 */
    RT_BEAM_PARAM_COLOR,      /* 4 */
    RT_BEAM_PARAM_INTENSITY,  /* 1 */
    RT_BEAM_PARAM_EXPOSURE,   /* 1 */
    RT_BEAM_PARAM_HEAD_RADIUS,  /* 1 (the attack's anatomy) */
    RT_BEAM_PARAM_ORB_RADIUS,   /* 1 */
    RT_BEAM_PARAM_ORB_STRENGTH, /* 1 */
    RT_BEAM_PARAM_TAPER,        /* 1 */
    RT_BEAM_PARAM_SURGE,        /* 1: surge amount */
    RT_BEAM_PARAM_COUNT
} rt_scene_beam_param;

/* Keyframes of one parameter: times strictly increasing; values has dim * count floats. */
typedef struct rt_scene_track {
    uint32_t count, dim;
    float *times;
    float *values;
} rt_scene_track;

typedef struct rt_scene_beam {
    vfx_beam base;      /* geometry (head .. eps, color) when not animated; the rest unused */
    rt_scene_track tracks[RT_BEAM_PARAM_COUNT];   /* count 0 = not animated */
    float loop_s;                                   /* >0: time wraps modulo loop_s */
    vfx_beam look;      /* falloff, ramp, intensity, exposure, flow, anatomy; geometry unused */
    uint32_t joint_count;                  /* 0 straight, 2..RT_SCENE_MAX_JOINTS: bending beam */
    float joints[RT_SCENE_MAX_JOINTS][3];  /* values when not animated */
    rt_scene_track joint_track;            /* dim 3 * joint_count; count 0 = not animated */
} rt_scene_beam;

typedef enum rt_scene_water_source {
    RT_SCENE_WATER_FILE = 0,        /* particle file (particle_file.h) */
    RT_SCENE_WATER_GENERATOR = 1,   /* static particles laid out by a generator */
    RT_SCENE_WATER_SIMULATION = 2,  /* an SPH set-up: tank, initial fluid block, paddle */
} rt_scene_water_source;

typedef enum rt_scene_generator {
    RT_SCENE_GEN_LAYERS = 0,   /* seed 000 Table 1: 24x24 squares per layer, stacked in y */
    RT_SCENE_GEN_BOX = 1,      /* a lattice filling [min, max] */
    RT_SCENE_GEN_SPHERE = 2,   /* a lattice inside a sphere, filled from the bottom */
} rt_scene_generator;

/* water.simulation.device: which solver steps the fluid (docs/scene-format.md) */
enum {
    RT_SCENE_SIM_AUTO = 0, /* the GPU on a hardware GL driver, the CPU on a software one (llvmpipe) */
    RT_SCENE_SIM_CPU = 1,
    RT_SCENE_SIM_GPU = 2,
};

typedef struct rt_scene_water {
    rt_scene_water_source source;
    double scene_origin[3];          /* the scene's origin, subtracted from a particle file */
    char path[RT_SCENE_PATH_MAX];   /* FILE */
    /* GENERATOR */
    rt_scene_generator generator;
    uint32_t count;                  /* also the SIMULATION particle count */
    float origin[3];                 /* layers: corner of the first layer */
    float spacing;                   /* layers: distance between neighbours */
    uint32_t layer_side;             /* layers: particles per side of a layer (24) */
    float box_min[3], box_max[3];    /* box generator, and SIMULATION's initial fluid block */
    float center[3];
    float radius;                    /* sphere */
    /* SIMULATION */
    float tank_min[3], tank_max[3];
    float gravity[3];
    float dt;                        /* simulation step in seconds */
    bool paddle;
    uint32_t paddle_axis;            /* 0 x, 1 y, 2 z: the axis the paddle moves along */
    float paddle_amplitude;          /* metres */
    float paddle_period_s;
    float paddle_ramp_s;             /* amplitude ramped in over this time (default one period) */
    bool no_slip;                    /* tank walls (all six faces) with wall-law friction */
    uint32_t solver;                 /* water.simulation.solver: 0 "wcsph", 1 "pbf" (rt_sph_solver); "pbf" */
    uint32_t settle_steps;           /* rt_sph_settle's steps at most before frame 0 (default 120; 0: none) */
    uint32_t device;                 /* water.simulation.device: RT_SCENE_SIM_AUTO (default), _CPU, _GPU */
    float impact_strength;           /* m/s: a beam striking the water pushes the fluid near the hit up to
                                      * this speed (rt_sph_impulse; default 4, 0: off) */
    float impact_radius;             /* m: within this of the hit (default 0.25) */
    /* rendering (seed 000): every field, type filled (next unset: the host chains the foam) */
    vfx_water_params params;
    /* water.foam: the foam layer and the spray at beam impacts (type filled; chained by the host) */
    vfx_water_foam foam;
} rt_scene_water;

typedef struct rt_scene_transfer_point {
    float scalar;
    float rgba[4];   /* alpha is opacity per unit length */
} rt_scene_transfer_point;

/* How the game animates a volume each frame (volume.animate): vertices ripple, the beams light
 * the scalar where they pass, and a bright band sweeps through the transfer function. */
typedef struct rt_scene_volume_animation {
    float ripple_amplitude;          /* radial displacement, fraction of the distance to the centre */
    float ripple_wavelength;         /* model units along the height */
    float ripple_period_s;
    float glow_gain;                 /* scalar added at a beam's axis */
    float glow_reach;                /* Gaussian reach in beam radii */
    float pulse_rgba[4];             /* the band's colour and extinction */
    float pulse_width;               /* half width in [0,1] of the transfer domain */
    float pulse_period_s;            /* one sweep from the domain's low to high end */
    float rim_gain;                  /* scalar added at boundary vertices seen edge-on */
    float rim_power;                 /* sharpness of the rim: gain (1 - |n.v|)^power */
    float hit_gain;                  /* scalar of the rings around a beam's strike point */
    float hit_wavelength;            /* ring spacing, world units */
    float hit_speed;                 /* ring speed outwards, world units per second */
    float hit_reach;                 /* rings fade as exp(-r / reach), world units */
} rt_scene_volume_animation;

typedef struct rt_scene_volume {
    bool generated;                  /* a generated grid instead of a file */
    char path[RT_SCENE_PATH_MAX];   /* .vtu, or .node (its .ele beside it) */
    char scalar[64];                 /* point-data array name; "" = the loader's default */
    uint32_t gen_cells;              /* generated: cells per axis (6 tets each) */
    float gen_min[3], gen_max[3];
    bool transfer_normalized;        /* control-point scalars are in [0,1] of the data range */
    uint32_t transfer_count;         /* 0 = the plugin's default ramp */
    uint32_t transfer_method;        /* vfx_volume_transfer_method ("exact", "preintegrated") */
    rt_scene_transfer_point transfer[RT_SCENE_MAX_TRANSFER];
    float ert_threshold;             /* 0 -> plugin default */
    uint32_t tiles, update_c, workers;
    float model[16];
    rt_scene_volume_animation anim;  /* per-frame changes (none when all zero) */
} rt_scene_volume;

/* "environment": the world around the meshes (absent: a clear colour, checkered meshes). */
typedef struct rt_scene_environment {
    bool sky;           /* "sky": "dusk" (the default) or "none" */
    float sun_dir[3];   /* "sun_dir": towards the sun; default (-0.45, 0.35, -0.82), low */
    float fog;          /* "fog": density per metre, 0..10; default 0 */
} rt_scene_environment;

typedef struct rt_scene {
    char name[128];
    char base_dir[RT_SCENE_PATH_MAX];
    double origin[3];                /* "origin": every position below (camera, meshes, water,
                                        beams, volume, particle files) is relative to it */
    rt_scene_camera camera;
    uint32_t mesh_count;
    rt_scene_mesh *meshes;
    uint32_t beam_count;
    rt_scene_beam *beams;
    vfx_beams_view beams_view;       /* saturation, saturate_c, far_distance, bloom settings */
    bool has_water;
    rt_scene_water water;
    bool has_volume;
    rt_scene_volume volume;
    rt_scene_environment environment;
} rt_scene;

/* Parses `len` bytes of JSON (no NUL needed). Relative paths resolve against `base_dir`
 * (NULL or "" -> the current directory). On error *out is NULL and err names the JSON path. */
vfx_result rt_scene_load_mem(const char *json, size_t len, const char *base_dir,
                              const rt_logger *logger, rt_scene **out, char *err, size_t errlen);
/* Reads and parses a scene file; relative paths resolve against the file's folder. */
vfx_result rt_scene_load_file(const char *path, const rt_logger *logger, rt_scene **out,
                               char *err, size_t errlen);
/* Frees a scene; NULL allowed. */
void rt_scene_free(rt_scene *scene);

/* Writes the beams at `time` (keyframes interpolated linearly, clamped at the ends, wrapped by
 * loop_s) into out[0..n), each with its type, falloff, ramp, intensity, exposure, flow and
 * anatomy; the joints of bending beams go to joints (xyz triples, room for joint_cap of them;
 * beams whose joints do not fit, or all with joints NULL, are left straight), each beam's
 * joint_first indexing into it; *joint_count (may be NULL) gets how many were written. Returns
 * how many beams were written (min(n, beam_count)). */
uint32_t rt_scene_beams_at(const rt_scene *scene, double time, vfx_beam *out, uint32_t n, float *joints,
                           uint32_t joint_cap, uint32_t *joint_count);
/* Linear interpolation of one track at time t into out[0..dim); clamped at the ends. */
void rt_scene_track_eval(const rt_scene_track *track, double t, float *out);

/* The water's initial particles (x,y,z interleaved, malloc'd; caller frees): read from the
 * file, laid out by the generator, or the simulation's initial fluid block. */
vfx_result rt_scene_water_particles(const rt_scene_water *water, float **xyz, uint32_t *count,
                                     char *err, size_t errlen);

/* Resamples the transfer function to n uniform RGBA entries over [first, last] control-point
 * scalar; smin and smax receive that domain (both 0 when normalized: the plugin uses the data
 * range). rgba must hold 4*n floats; n >= 2. */
void rt_scene_transfer_sample(const rt_scene_volume *v, uint32_t n, float *rgba, float *smin,
                               float *smax);

/* A generated tetrahedral grid: gen_cells^3 cubes of 6 positively oriented tets each, with the
 * scalar 1 - |p - centre| / half-diagonal per point. Arrays are malloc'd; caller frees. */
vfx_result rt_scene_volume_generate(const rt_scene_volume *v, float **points, uint32_t *point_count,
                                     uint32_t **tets, uint32_t *tet_count, float **scalar,
                                     char *err, size_t errlen);

#endif
