/* tet_render_internal.h — the single-worker scan engine of tet_render.c, exposed for the MPI
 * backend (tet_mpi.c): one process's partition state (view-space vertices, the depth-sorted
 * cell keys of every partition, its per-pixel segment lists and local ERT table). Not part of
 * the plugin's public API; every process that builds one from the same inputs gets the same
 * key order, so a cell range is a valid unit of work on any of them. */
#ifndef TET_RENDER_INTERNAL_H
#define TET_RENDER_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include "tet_render.h"

/* One ray segment as exchanged between processes: ray distances and premultiplied RGBA. */
typedef struct tet_rseg {
    float zf, zb;
    float r, g, b, a;
} tet_rseg;

typedef struct tet_local tet_local;

/* Validates the inputs as tet_render_workers does and prepares a scan split into parts
 * partitions (contiguous ranges of the mesh's cell order, each sorted front to back), building
 * the keys of partition own (its NaN cells counted). The arguments must outlive the result.
 * Returns TET_OK or an error code with a message in err. */
tet_result tet_local_create(const tet_mesh *mesh, const tet_camera *cam,
                         const tet_tf *tf, const tet_options *opts, int parts, int own,
                         tet_local **out, char *err, size_t errlen);
/* Frees a scan state; NULL allowed. */
void tet_local_destroy(tet_local *L);
/* The key range [k0, k1) of partition part (its keys are built first if they were not). */
void tet_local_part(tet_local *L, int part, uint32_t *k0, uint32_t *k1);
/* Cells of partition part (an upper bound of its keys, known without building them). */
uint32_t tet_local_part_cells(const tet_local *L, int part);
/* Builds the keys of every partition that overlaps [k0, k1), before scanning keys there. */
void tet_local_need(tet_local *L, uint32_t k0, uint32_t k1);
/* Scan-converts key k (of a built partition) into the local lists unless the local ERT table proves it hidden.
 * Returns 0, or -1 when out of memory. */
int tet_local_scan(tet_local *L, uint32_t k);
/* Rebuilds the local ERT table from the local lists only (paper 3.1.1). */
void tet_local_update_table(tet_local *L);
/* Writes the D*D local table as deepest where terminated, +INFINITY elsewhere. */
void tet_local_table_get(const tet_local *L, float *enc);
/* Merges an encoded table into the local one: the terminated entry with the smaller deepest
 * wins (paper 3.2). */
void tet_local_table_merge(tet_local *L, const float *enc);
/* D of the ERT table. */
int tet_local_tiles_d(const tet_local *L);
/* Exports the lists of pixels [p0, p1) in depth order: offsets (p1 - p0 + 1 entries) always,
 * segs (offsets[p1 - p0] entries) when not NULL. Returns the segment count. */
size_t tet_local_export(const tet_local *L, size_t p0, size_t p1, uint32_t *offsets,
                            tet_rseg *segs);
/* The counters of this scan (cells_nan: those of the own partition, set at creation). */
tet_counters *tet_local_counters(tet_local *L);

#endif
