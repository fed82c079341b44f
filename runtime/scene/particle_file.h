/* particle_file.h — the particle file: little-endian float32 x,y,z triples, nothing else
 * (12 bytes per particle, no header). Zero particles (an empty file) is a valid file. */
#ifndef RT_PARTICLE_FILE_H
#define RT_PARTICLE_FILE_H

#include <stddef.h>
#include <stdint.h>
#include <volfx/volfx.h>

/* Files holding more particles than this are refused before anything is read (50 MB). The same
 * number as a scene's particle cap (RT_SCENE_MAX_PARTICLES), so a scene's water from a file
 * and from a generator are bounded alike. */
#define RT_PARTICLE_FILE_MAX_COUNT (1u << 22) /* 4,194,304 */

/* Decodes `size` bytes into a malloc'd xyz array (NULL when count is 0). Errors: size not a
 * multiple of 12 (VFX_ERR_FORMAT, names the size), NaN/Inf (VFX_ERR_FORMAT, names the particle
 * index and coordinate), above the cap (VFX_ERR_INVALID_ARGUMENT). */
vfx_result rt_particle_file_parse(const void *data, size_t size, float **xyz, uint32_t *count,
                                   char *err, size_t errlen);
/* Reads a particle file (errors also name the path; VFX_ERR_IO when it cannot be read). */
vfx_result rt_particle_file_load(const char *path, float **xyz, uint32_t *count, char *err,
                                  size_t errlen);
/* Writes `count` xyz triples; refuses NaN/Inf (VFX_ERR_INVALID_ARGUMENT) before writing. */
vfx_result rt_particle_file_save(const char *path, const float *xyz, uint32_t count, char *err,
                                  size_t errlen);

#endif
