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

/* X(ID, ABI field, scene key or "-", lo, hi, flags, note): every vector component is checked. */
#define VFX_RANGE_TABLE(X) \
    X(WATER_H, "vfx_water_params.h", "water.h", 0, 1e3, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "0: 2 x the particles' spacing") \
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
    X(BEAMS_C, "vfx_beams_view.saturate_c", "beam_settings.c", 0, 1e6, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "") \
    X(BEAMS_FAR, "vfx_beams_view.far_distance", "beam_settings.far_distance", 0, 1e6, 0, "0: the camera's far plane") \
    X(BEAMS_MARCH_SAMPLES, "vfx_lab_beams.march_samples", "beam_settings.march_samples", 1, 4096, VFX_RANGE_INT | VFX_RANGE_ZERO, "") \
    X(BEAMS_BLOOM_STRENGTH, "vfx_beams_view.bloom_strength", "beam_settings.bloom_strength", 0, 1e6, 0, "0: 0.6") \
    X(BEAMS_BLOOM_LEVELS, "vfx_beams_view.bloom_levels", "beam_settings.bloom_levels", 1, 8, VFX_RANGE_INT | VFX_RANGE_ZERO, "") \
    X(VOLUME_ERT_THRESHOLD, "vfx_volume_view.ert_threshold", "volume.ert_threshold", 0, 1, VFX_RANGE_LO_OPEN | VFX_RANGE_ZERO, "") \
    X(VOLUME_TILES, "vfx_volume_view.tiles", "volume.tiles", 1, 1024, VFX_RANGE_INT | VFX_RANGE_ZERO, "a DxD table per worker") \
    X(VOLUME_UPDATE_C, "vfx_volume_view.update_c", "volume.update_c", 1, 1048576, VFX_RANGE_INT | VFX_RANGE_ZERO, "") \
    X(VOLUME_WORKERS, "vfx_volume_view.workers", "volume.workers", 0, 256, VFX_RANGE_INT, "0: the number of cores")

typedef enum vfx_range_id {
#define VFX_RANGE_ENUM_(id, field, key, lo, hi, flags, note) VFX_RANGE_##id,
    VFX_RANGE_TABLE(VFX_RANGE_ENUM_)
#undef VFX_RANGE_ENUM_
    VFX_RANGE_COUNT
} vfx_range_id;

#endif
