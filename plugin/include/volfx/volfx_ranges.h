/* volfx_ranges.h — the documented range of every numeric field of the ABI, one row each, in one
 * place. The plugin checks the host's structs against it (a value outside is refused with
 * VFX_ERR_INVALID_ARGUMENT naming the field, never replaced by a default), the sample host's
 * scene loader checks the scene keys that feed those fields against the same rows, and the
 * "Ranges" table of docs/scene-format.md is generated from it (test unit/param_ranges fails when
 * they differ). A host may use it to check its own values first. */
#ifndef VOLFX_RANGES_H
#define VOLFX_RANGES_H

#include <stdint.h>

/* Row flags. */
#define VFX_RANGE_LO_OPEN 1u  /* the value must be > lo (>= lo otherwise) */
#define VFX_RANGE_ZERO 2u     /* 0 means the field's default (ABI; a scene leaves the key out) */
#define VFX_RANGE_INT 4u      /* an unsigned integer field */
#define VFX_RANGE_ANY 8u      /* every value is valid (a GL name, an id, a count the host's array
                                 holds): the note says what is checked instead, lo and hi unused */
#define VFX_RANGE_MASK 16u    /* a bit mask: every bit must be one of hi's (lo unused) */

/* The ends of the rows whose only bound is being finite. */
#define VFX_RANGE_FLOAT_MAX 3.4028234663852886e38
#define VFX_RANGE_DOUBLE_MAX 1.7976931348623157e308

/* X(ID, ABI field, scene key or "-", lo, hi, flags, note): every vector component is checked.
 * A VFX_RANGE_<ID> is the row's place in this table, for use at compile time (no ABI call takes
 * one): a row is added beside its struct's, so the numbers of the rows after it move between
 * versions; name rows by their ID, never by number. */
#define VFX_RANGE_TABLE(X) \
    X(WATER_H, "vfx_water_params.h", "water.h", 1e-12, 1e3, VFX_RANGE_ZERO, "0: 2 x the particles' spacing, refused below 1e-12 too (h^3 is a normal float32)") \
    X(WATER_THRESHOLD, "vfx_water_params.threshold", "water.threshold", 0, 1e3, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "") \
    X(WATER_MAX_SAMPLES, "vfx_water_params.max_samples", "water.quality.max_samples", 1, 4096, VFX_RANGE_INT | VFX_RANGE_ZERO, "a loop bound per pixel") \
    X(WATER_STEP, "vfx_water_params.step", "water.quality.step", 0, 1e3, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "and within [h/1024, h] once h is known") \
    X(WATER_REFINE_ITERS, "vfx_water_params.refine_iters", "water.quality.refine_iters", 1, 64, VFX_RANGE_INT | VFX_RANGE_ZERO, "") \
    X(WATER_PYRAMID_LEVEL, "vfx_water_params.pyramid_level", "water.quality.pyramid_level", 1, 12, VFX_RANGE_INT | VFX_RANGE_ZERO, "") \
    X(WATER_COLOR, "vfx_water_params.color", "water.color", 0, 1, VFX_RANGE_ZERO, "all 0: sea water") \
    X(WATER_ABSORPTION, "vfx_water_params.absorption", "water.absorption", 0, 1e3, VFX_RANGE_ZERO, "") \
    X(WATER_IOR, "vfx_water_params.ior", "water.ior", 1, 3, VFX_RANGE_ZERO, "") \
    X(WATER_ANISO_RADIUS, "vfx_water_params.aniso_radius", "-", 0.5, 4, VFX_RANGE_ZERO, "in units of h") \
    X(WATER_ANISO_MAX_STRETCH, "vfx_water_params.aniso_max_stretch", "-", 1, 64, VFX_RANGE_ZERO, "") \
    X(WATER_ANISO_MIN_NEIGHBOURS, "vfx_water_params.aniso_min_neighbours", "-", 1, 10000, VFX_RANGE_INT | VFX_RANGE_ZERO, "") \
    X(WATER_ANISO_SCALE, "vfx_water_params.aniso_scale", "-", 0.25, 4, VFX_RANGE_ZERO, "") \
    X(WATER_ANISO_SMOOTHING, "vfx_water_params.aniso_smoothing", "-", 0, 1, 0, "") \
    X(WATER_METHOD, "vfx_water_params.method", "-", 3, 4, VFX_RANGE_INT | VFX_RANGE_ZERO, "3 tile, 4 paper") \
    X(WATER_PRESET, "vfx_water_params.preset", "-", 1, 4, VFX_RANGE_INT | VFX_RANGE_ZERO, "1 low .. 4 ultra") \
    X(WATER_KERNEL, "vfx_water_params.kernel", "-", 1, 2, VFX_RANGE_INT | VFX_RANGE_ZERO, "1 isotropic, 2 anisotropic") \
    X(WATER_FEATURES_OFF, "vfx_water_params.features_off", "-", 0, 0xc000, VFX_RANGE_MASK, "VFX_WATER_NO_SPRAY, VFX_WATER_NO_SSR") \
    X(WATER_DIFFUSE_MAX, "vfx_water_params.diffuse_max", "water.diffuse.max", 1, 4194304, VFX_RANGE_INT | VFX_RANGE_ZERO, "") \
    X(WATER_GRAVITY, "vfx_water_params.gravity", "water.diffuse.gravity", -1e4, 1e4, VFX_RANGE_ZERO, "all 0: (0, -9.81, 0)") \
    X(WATER_TRAPPED_AIR, "vfx_water_params.trapped_air", "water.diffuse.trapped_air", 0, 1e4, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "each 0: its default; min < max") \
    X(WATER_WAVE_CREST, "vfx_water_params.wave_crest", "water.diffuse.wave_crest", 0, 1e4, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "each 0: its default; min < max") \
    X(WATER_ENERGY, "vfx_water_params.energy", "water.diffuse.energy", 0, 1e4, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "each 0: its default; min < max") \
    X(WATER_RATE_TRAPPED_AIR, "vfx_water_params.rate_trapped_air", "water.diffuse.rate_trapped_air", 0, 1e4, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "0: 10") \
    X(WATER_RATE_WAVE_CREST, "vfx_water_params.rate_wave_crest", "water.diffuse.rate_wave_crest", 0, 1e4, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "0: 25") \
    X(WATER_LIFETIME, "vfx_water_params.lifetime", "water.diffuse.lifetime", 0, 60, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "0: 1.5") \
    X(WATER_BUOYANCY, "vfx_water_params.buoyancy", "water.diffuse.buoyancy", 0, 20, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "0: 2") \
    X(WATER_DRAG, "vfx_water_params.drag", "water.diffuse.drag", 0, 60, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "0: 8") \
    X(WATER_SPRAY_BELOW, "vfx_water_params.spray_below", "water.diffuse.spray_below", 1, 10000, VFX_RANGE_INT | VFX_RANGE_ZERO, "0: 6; <= bubble_above") \
    X(WATER_BUBBLE_ABOVE, "vfx_water_params.bubble_above", "water.diffuse.bubble_above", 1, 10000, VFX_RANGE_INT | VFX_RANGE_ZERO, "0: 20") \
    X(PARTICLE_COUNT, "vfx_particle_view.count", "-", 0, 0, VFX_RANGE_ANY, "the chunk's columns hold count; a total the plugin cannot allocate is refused") \
    X(PARTICLE_REVISION, "vfx_particle_view.revision", "-", 0, 0, VFX_RANGE_ANY, "compared for change only") \
    X(GPU_COLUMN_BUFFER, "vfx_gpu_column.buffer", "-", 0, 0, VFX_RANGE_ANY, "a GL buffer name, checked as one") \
    X(GPU_COLUMN_STRIDE, "vfx_gpu_column.stride", "-", 0, 0, VFX_RANGE_ANY, "checked against the buffer: a multiple of 4, at least the element") \
    X(GPU_COLUMN_OFFSET, "vfx_gpu_column.offset", "-", 0, 0, VFX_RANGE_ANY, "checked against the buffer: a multiple of 4, the last element inside") \
    X(BEAM_HEAD, "vfx_beam.head", "beams[i].head", -VFX_RANGE_FLOAT_MAX, VFX_RANGE_FLOAT_MAX, 0, "finite") \
    X(BEAM_DIR, "vfx_beam.dir", "beams[i].dir", -VFX_RANGE_FLOAT_MAX, VFX_RANGE_FLOAT_MAX, 0, "finite, not all 0") \
    X(WATER_FOAM_LAYER, "vfx_water_foam.layer", "-", 0, 2, VFX_RANGE_INT, "0 the preset's, 1 on, 2 off") \
    X(WATER_FOAM_IMPACTS, "vfx_water_foam.impacts", "-", 0, 2, VFX_RANGE_INT, "0 on, 1 on, 2 off") \
    X(WATER_FOAM_LIFETIME, "vfx_water_foam.lifetime", "water.foam.lifetime", 0.05, 600, VFX_RANGE_ZERO, "seconds; 0: 3") \
    X(WATER_FOAM_CELL, "vfx_water_foam.cell", "water.foam.cell", 0.25, 2, VFX_RANGE_ZERO, "in units of h; 0: 0.5") \
    X(WATER_FOAM_DIFFUSION, "vfx_water_foam.diffusion", "water.foam.diffusion", 0, 100, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "h^2 / s; 0: 0.5") \
    X(WATER_FOAM_DEPOSIT, "vfx_water_foam.deposit", "water.foam.deposit", 0, 1e4, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "per foam particle per second; 0: 0.1") \
    X(WATER_FOAM_IMPACT_RATE, "vfx_water_foam.impact_rate", "water.foam.impact_rate", 0, 1e6, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "drops per second; 0: 600") \
    X(WATER_FOAM_IMPACT_SPEED, "vfx_water_foam.impact_speed", "water.foam.impact_speed", 0, 100, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "in units of sqrt(|g| h); 0: 4") \
    X(BEAM_LENGTH, "vfx_beam.length", "beams[i].length", 0, 1e6, 0, "") \
    X(BEAM_RADIUS, "vfx_beam.radius", "beams[i].radius", 0, 1e6, VFX_RANGE_LO_OPEN, "") \
    X(BEAM_A, "vfx_beam.a", "beams[i].a", 0, 1e6, 0, "") \
    X(BEAM_B, "vfx_beam.b", "beams[i].b", 0, 1e6, 0, "") \
    X(BEAM_EPS, "vfx_beam.eps", "beams[i].eps", 0, 1e6, 0, "") \
    X(BEAM_COLOR, "vfx_beam.color", "beams[i].color", 0, 1000, VFX_RANGE_ZERO, "all 0: white") \
    X(BEAM_INTENSITY, "vfx_beam.intensity", "beams[i].intensity", 0, 1e6, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "0: 1") \
    X(BEAM_EXPOSURE, "vfx_beam.exposure", "beams[i].exposure", -64, 64, 0, "stops applied to H") \
    X(BEAM_FLOW_AMOUNT, "vfx_beam.flow_amount", "beams[i].flow.amount", 0, 1, 0, "") \
    X(BEAM_FLOW_SPEED, "vfx_beam.flow_speed", "beams[i].flow.speed", -1e6, 1e6, 0, "") \
    X(BEAM_FLOW_SCALE, "vfx_beam.flow_scale", "beams[i].flow.scale", 0, 1e6, 0, "0: 2 x radius") \
    X(BEAM_FLOW_TWIST, "vfx_beam.flow_twist", "beams[i].flow.twist", -64, 64, 0, "0: 1 turn per flow wavelength") \
    X(BEAM_HEAD_RADIUS, "vfx_beam.head_radius", "beams[i].head_radius", 0, 1e6, 0, "0: radius") \
    X(BEAM_ORB_RADIUS, "vfx_beam.orb_radius", "beams[i].orb_radius", 0, 1e6, 0, "0: no orb") \
    X(BEAM_ORB_STRENGTH, "vfx_beam.orb_strength", "beams[i].orb_strength", 0, 1e6, 0, "0: a") \
    X(BEAM_ORB_PULSE, "vfx_beam.orb_pulse", "beams[i].orb.pulse", 0, 1, 0, "") \
    X(BEAM_ORB_PULSE_HZ, "vfx_beam.orb_pulse_hz", "beams[i].orb.pulse_hz", 0, 1e6, 0, "") \
    X(BEAM_TAPER, "vfx_beam.taper", "beams[i].taper", 0, 0.95, 0, "") \
    X(BEAM_SURGE_AMOUNT, "vfx_beam.surge_amount", "beams[i].surge", 0, 4, 0, "") \
    X(BEAM_SURGE_WAVELENGTH, "vfx_beam.surge_wavelength", "beams[i].surges.wavelength", 1e-6, 1e6, VFX_RANGE_ZERO, "0: 8 x radius") \
    X(BEAM_SURGE_SPEED, "vfx_beam.surge_speed", "beams[i].surges.speed", -1e6, 1e6, 0, "") \
    X(BEAM_CORE, "vfx_beam.core", "beams[i].core", 0, 1, 0, "") \
    X(BEAM_FALLOFF, "vfx_beam.falloff", "-", 1, 2, VFX_RANGE_INT | VFX_RANGE_ZERO, "1 smooth, 2 hard") \
    X(BEAM_RAMP, "vfx_beam.ramp", "-", 1, 2, VFX_RANGE_INT | VFX_RANGE_ZERO, "1 hot, 2 thesis") \
    X(BEAM_FLOW_KIND, "vfx_beam.flow_kind", "-", 0, 1, VFX_RANGE_INT, "0 noise, 1 spiral") \
    X(BEAM_JOINT_FIRST, "vfx_beam.joint_first", "-", 0, 0, VFX_RANGE_ANY, "joint_first + joint_count <= the view's joint_count") \
    X(BEAM_JOINT_COUNT, "vfx_beam.joint_count", "-", 2, 6, VFX_RANGE_INT | VFX_RANGE_ZERO, "0: a straight beam") \
    X(BEAMS_COUNT, "vfx_beams_view.count", "-", 0, 1048576, VFX_RANGE_INT, "") \
    X(BEAMS_SATURATION, "vfx_beams_view.saturation", "-", 0, 1, VFX_RANGE_INT, "0 clamp, 1 smooth") \
    X(BEAMS_BLOOM, "vfx_beams_view.bloom", "-", 1, 2, VFX_RANGE_INT | VFX_RANGE_ZERO, "1 on, 2 off") \
    X(BEAMS_JOINT_COUNT, "vfx_beams_view.joint_count", "-", 0, 0, VFX_RANGE_ANY, "the joints array's triples") \
    X(BEAMS_C, "vfx_beams_view.saturate_c", "beam_settings.c", 0, 1e6, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "") \
    X(BEAMS_FAR, "vfx_beams_view.far_distance", "beam_settings.far_distance", 0, 1e6, 0, "0: the camera's far plane") \
    X(BEAMS_BLOOM_STRENGTH, "vfx_beams_view.bloom_strength", "beam_settings.bloom_strength", 0, 1e6, 0, "0: 0.6") \
    X(BEAMS_BLOOM_LEVELS, "vfx_beams_view.bloom_levels", "beam_settings.bloom_levels", 1, 8, VFX_RANGE_INT | VFX_RANGE_ZERO, "") \
    X(VOLUME_POINT_COUNT, "vfx_volume_view.point_count", "-", 0, 0, VFX_RANGE_ANY, "the points array's; every tet index is checked against it") \
    X(VOLUME_TET_COUNT, "vfx_volume_view.tet_count", "-", 0, 0, VFX_RANGE_ANY, "the tets array's; a mesh the plugin cannot allocate is refused") \
    X(VOLUME_SCALAR_MIN, "vfx_volume_view.scalar_min", "-", -VFX_RANGE_FLOAT_MAX, VFX_RANGE_FLOAT_MAX, 0, "finite") \
    X(VOLUME_SCALAR_MAX, "vfx_volume_view.scalar_max", "-", -VFX_RANGE_FLOAT_MAX, VFX_RANGE_FLOAT_MAX, 0, "finite; equal to scalar_min: the data's range") \
    X(VOLUME_TRANSFER_COUNT, "vfx_volume_view.transfer_count", "-", 2, 1024, VFX_RANGE_INT | VFX_RANGE_ZERO, "0: the default ramp") \
    X(VOLUME_TRANSFER_METHOD, "vfx_volume_view.transfer_method", "-", 0, 1, VFX_RANGE_INT, "0 exact, 1 pre-integrated") \
    X(VOLUME_MODEL, "vfx_volume_view.model", "-", -VFX_RANGE_FLOAT_MAX, VFX_RANGE_FLOAT_MAX, VFX_RANGE_ZERO, "all 0: identity") \
    X(VOLUME_REVISION, "vfx_volume_view.revision", "-", 0, 0, VFX_RANGE_ANY, "compared for change only") \
    X(VOLUME_ERT_THRESHOLD, "vfx_volume_view.ert_threshold", "volume.ert_threshold", 0, 1, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "") \
    X(VOLUME_TILES, "vfx_volume_view.tiles", "volume.tiles", 1, 1024, VFX_RANGE_INT | VFX_RANGE_ZERO, "a DxD table per worker") \
    X(VOLUME_UPDATE_C, "vfx_volume_view.update_c", "volume.update_c", 1, 1048576, VFX_RANGE_INT | VFX_RANGE_ZERO, "") \
    X(VOLUME_WORKERS, "vfx_volume_view.workers", "volume.workers", 0, 256, VFX_RANGE_INT, "0: the number of cores") \
    X(FRAME_FRAMEBUFFER, "vfx_frame_view.framebuffer", "-", 0, 0, VFX_RANGE_ANY, "a GL framebuffer name, checked as one") \
    X(FRAME_COLOR_TEXTURE, "vfx_frame_view.color_texture", "-", 0, 0, VFX_RANGE_ANY, "a GL texture name, checked as one") \
    X(FRAME_DEPTH_TEXTURE, "vfx_frame_view.depth_texture", "-", 0, 0, VFX_RANGE_ANY, "a GL texture name, checked as one") \
    X(FRAME_WIDTH, "vfx_frame_view.width", "-", 1, 16384, VFX_RANGE_INT, "") \
    X(FRAME_HEIGHT, "vfx_frame_view.height", "-", 1, 16384, VFX_RANGE_INT, "") \
    X(FRAME_VIEW_MATRIX, "vfx_frame_view.view", "-", -VFX_RANGE_FLOAT_MAX, VFX_RANGE_FLOAT_MAX, 0, "finite, invertible") \
    X(FRAME_PROJ, "vfx_frame_view.proj", "-", -VFX_RANGE_FLOAT_MAX, VFX_RANGE_FLOAT_MAX, 0, "finite, view x proj invertible") \
    X(FRAME_EYE, "vfx_frame_view.eye", "-", -VFX_RANGE_FLOAT_MAX, VFX_RANGE_FLOAT_MAX, VFX_RANGE_ZERO, "the view matrix's eye") \
    X(FRAME_NEAR, "vfx_frame_view.near_plane", "-", 0, VFX_RANGE_FLOAT_MAX, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "proj's near") \
    X(FRAME_FAR, "vfx_frame_view.far_plane", "-", 0, VFX_RANGE_FLOAT_MAX, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "proj's far, > near_plane") \
    X(FRAME_FOV_Y, "vfx_frame_view.fov_y", "-", 0, 3.1415925, 0, "radians, below pi") \
    X(FRAME_EFFECTS, "vfx_frame_view.effects", "-", 0, 7, VFX_RANGE_MASK, "VFX_EFFECT_BIT of each effect; 0: all") \
    X(FRAME_ORIGIN, "vfx_frame_view.origin", "-", -VFX_RANGE_DOUBLE_MAX, VFX_RANGE_DOUBLE_MAX, 0, "finite; far from the content: warned") \
    X(FRAME_COLOR_HDR, "vfx_frame_view.color_hdr", "-", 0, 1, VFX_RANGE_INT, "") \
    X(FRAME_ENVIRONMENT_CUBEMAP, "vfx_frame_view.environment_cubemap", "-", 0, 0, VFX_RANGE_ANY, "a GL cubemap texture name") \
    X(FRAME_VIEW_ID, "vfx_frame_view.view_id", "-", 0, 0, VFX_RANGE_ANY, "any id") \
    X(FRAME_LAYER_TEXTURE, "vfx_frame_view.layer_texture", "-", 0, 0, VFX_RANGE_ANY, "a GL RGBA16F texture name, checked as one") \
    X(FRAME_DEPTH_RENDERBUFFER, "vfx_frame_depth.depth_renderbuffer", "-", 0, 0, VFX_RANGE_ANY, "a GL renderbuffer name, checked as one") \
    X(FRAME_DEPTH_FRAMEBUFFER, "vfx_frame_depth.depth_framebuffer", "-", 0, 0, VFX_RANGE_ANY, "a GL framebuffer name, checked as one; not with depth_renderbuffer") \
    X(FRAME_DEPTH_FLIP_Y, "vfx_frame_depth.flip_y", "-", 0, 0, VFX_RANGE_ANY, "0 or nonzero") \
    X(FRAME_DEPTH_CONVENTION, "vfx_frame_depth.depth_convention", "-", 0, 1, VFX_RANGE_INT, "0 standard, 1 zero to one") \
    X(GL_STATE_SKIP_RESTORE, "vfx_gl_state_desc.skip_restore", "-", 0, 0, VFX_RANGE_ANY, "0 or nonzero") \
    X(LIGHTS_CAPACITY, "vfx_lights.capacity", "-", 0, 0, VFX_RANGE_ANY, "entries at lights; the plugin writes at most this many") \
    X(IMPACT_EVENTS_CAPACITY, "vfx_impact_events.capacity", "-", 0, 0, VFX_RANGE_ANY, "entries at events; the plugin writes at most this many")

typedef enum vfx_range_id {
#define VFX_RANGE_ENUM_(id, field, key, lo, hi, flags, note) VFX_RANGE_##id,
    VFX_RANGE_TABLE(VFX_RANGE_ENUM_)
#undef VFX_RANGE_ENUM_
    VFX_RANGE_COUNT
} vfx_range_id;

#endif
