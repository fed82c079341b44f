/* sim_gpu.h — the GPU PBF solver (sph_gpu.h) as the device of the ECS simulation system
 * (sim_system.h rt_sim_system_set_device): the system keeps its clock, settle, labels and sim.*
 * figures; the particles it binds at its first run are copied into GL buffers and stepped there
 * from then on (the world's rows keep that first state), and a renderer reads them as GL buffer
 * columns (rt_sim_gpu_view) with no CPU copy. Needs the GL 4.5 context current at every run. */
#ifndef RT_SIM_GPU_H
#define RT_SIM_GPU_H

#include "sim/sim_system.h"
#include "sim/sph_gpu.h"

typedef struct rt_sim_gpu rt_sim_gpu;

/* Makes sys step on the GPU from its next run on (the system owns the result, freed with it).
 * The GPU solver is made at that run; its errors (e.g. VFX_ERR_UNSUPPORTED for a mesh collider)
 * fail the run with the system's label. */
vfx_result rt_sim_gpu_attach(rt_sim_system *sys, rt_sim_gpu **out, char *err, size_t errlen);
/* The state as one particle view of GL buffer columns (gpu_pos, gpu_vel; revision changes every
 * step); false before the first run made the GPU solver. */
bool rt_sim_gpu_view(const rt_sim_gpu *g, vfx_particle_view *out);

#endif
