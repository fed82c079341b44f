/* tet_render_internal.h — the single-worker scan engine of tet_render.c, exposed for the MPI
 * backend (tet_mpi.c): one process's partition state (view-space vertices, the depth-sorted
 * cell keys of every partition, its per-pixel segment lists and local ERT table). Not part of
 * the plugin's public API; every process that builds one from the same inputs gets the same
 * key order, so a cell range is a valid unit of work on any of them. */
#ifndef VFX_TET_RENDER_INTERNAL_H
#define VFX_TET_RENDER_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include "tet_render.h"

/* One ray segment as exchanged between processes: ray distances and premultiplied RGBA. */
typedef struct vfx_tet_rseg {
    float zf, zb;
    float r, g, b, a;
} vfx_tet_rseg;

typedef struct vfx_tet_local vfx_tet_local;

/* Validates the inputs as vfx_tet_render_workers does and prepares a scan split into parts
 * partitions (contiguous ranges of the mesh's cell order, each sorted front to back), building
 * the keys of partition own (its NaN cells counted). The arguments must outlive the result.
 * Returns VFX_OK or an error code with a message in err. */
int vfx_tet_local_create(const vfx_tet_mesh *mesh, const vfx_tet_camera *cam,
                         const vfx_tet_tf *tf, const vfx_tet_options *opts, int parts, int own,
                         vfx_tet_local **out, char err[256]);
/* Frees a scan state; NULL allowed. */
void vfx_tet_local_destroy(vfx_tet_local *L);
/* The key range [k0, k1) of partition part (its keys are built first if they were not). */
void vfx_tet_local_part(vfx_tet_local *L, int part, uint32_t *k0, uint32_t *k1);
/* Cells of partition part (an upper bound of its keys, known without building them). */
uint32_t vfx_tet_local_part_cells(const vfx_tet_local *L, int part);
/* Builds the keys of every partition that overlaps [k0, k1), before scanning keys there. */
void vfx_tet_local_need(vfx_tet_local *L, uint32_t k0, uint32_t k1);
/* Scan-converts key k (of a built partition) into the local lists unless the local ERT table proves it hidden.
 * Returns 0, or -1 when out of memory. */
int vfx_tet_local_scan(vfx_tet_local *L, uint32_t k);
/* Rebuilds the local ERT table from the local lists only (paper 3.1.1). */
void vfx_tet_local_update_table(vfx_tet_local *L);
/* Writes the D*D local table as deepest where terminated, +INFINITY elsewhere. */
void vfx_tet_local_table_get(const vfx_tet_local *L, float *enc);
/* Merges an encoded table into the local one: the terminated entry with the smaller deepest
 * wins (paper 3.2). */
void vfx_tet_local_table_merge(vfx_tet_local *L, const float *enc);
/* D of the ERT table. */
int vfx_tet_local_tiles_d(const vfx_tet_local *L);
/* Exports the lists of pixels [p0, p1) in depth order: offsets (p1 - p0 + 1 entries) always,
 * segs (offsets[p1 - p0] entries) when not NULL. Returns the segment count. */
size_t vfx_tet_local_export(const vfx_tet_local *L, size_t p0, size_t p1, uint32_t *offsets,
                            vfx_tet_rseg *segs);
/* The counters of this scan (cells_nan: those of the own partition, set at creation). */
vfx_tet_counters *vfx_tet_local_counters(vfx_tet_local *L);

#endif
