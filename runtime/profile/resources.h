/* resources.h — process and GL resource counts for long-run leak checks. */
#ifndef RT_RESOURCES_H
#define RT_RESOURCES_H

#include <stdint.h>

typedef struct rt_gl_object_counts {
    uint32_t buffers, textures, framebuffers, vertex_arrays, programs, shaders, queries;
    uint32_t total;
} rt_gl_object_counts;

/* Resident set size of this process in bytes (from /proc/self/statm; 0 when unavailable). */
uint64_t rt_resident_bytes(void);
/* Counts live GL object names 1..max_name of each kind in the current context (glIs*): the
 * names a leak would pile up. Cost grows with max_name: for sampling, not per frame. */
rt_gl_object_counts rt_gl_count_objects(uint32_t max_name);

#endif
