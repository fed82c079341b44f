/* pbf_cases.h — the PBF solvers' shared test cases (test_pbf on the CPU, test_pbf_gpu on the GPU):
 * each makes the solver and its particles, so both suites step the same set-up. `threads` is
 * the CPU solver's thread count (PBF is bitwise the same over thread counts: test_pbf). */
#ifndef VFX_TEST_PBF_CASES_H
#define VFX_TEST_PBF_CASES_H

#include "sim/sph.h"

/* A PBF solver over d (d.solver set to PBF), asserting that it is made. */
rt_sph *pbf_make(rt_sph_desc d);
/* A 10 x 20 x 6 cm box of 1 cm spacing, defaults otherwise. */
rt_sph_desc pbf_small_box(uint32_t threads);
/* The small box with 300 particles on one point (0.05, 0.1, 0.03). */
rt_sph *pbf_case_one_point(uint32_t threads);
/* The small box, velocity limit 1 m/s, 3 particles, the third falling at 50 m/s. */
rt_sph *pbf_case_speed_cap(uint32_t threads);
/* A column (8 x 13 x 4 cm) above a box wall one spacing thick at y = 0.08 (the plate
 * |y - 0.08| < 0.005, wider than the 20 x 30 x 4 cm domain). */
rt_sph *pbf_case_thin_wall(uint32_t threads);
/* The resting pool: a 60 x 40 x 30 cm tank of 2 cm spacing filled 12 cm deep (6 layers, 2,700
 * particles, as the default scene's pool), unsettled. */
rt_sph *pbf_case_pool(uint32_t threads);

#endif
