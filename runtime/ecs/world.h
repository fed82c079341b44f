/* world.h — the ECS world: generational entity ids, components registered at run time,
 * archetype tables stored as structure of arrays, queries and a phase scheduler.
 *
 * Storage: entities with the same set of components share a table; each component is one
 * contiguous column in that table, and a component declared with fields > 1 is stored as one
 * contiguous column per field (x[], y[], z[]), so a whole column goes to the GPU in one call
 * with no copy. Columns are 64-byte aligned. A column pointer stays valid until the next
 * structural change (spawn, despawn, add, remove, reorder) of that table.
 * No global state: everything lives in a vfx_world. Not thread-safe; systems run in order. */
#ifndef VFX_ECS_WORLD_H
#define VFX_ECS_WORLD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "core/log.h"

/* Entity id: low 32 bits index, high 32 bits generation (>= 1). 0 is never a live entity. */
typedef uint64_t vfx_entity;
#define VFX_ENTITY_NULL ((vfx_entity)0)
static inline uint32_t vfx_entity_index(vfx_entity e) { return (uint32_t)e; }
static inline uint32_t vfx_entity_generation(vfx_entity e) { return (uint32_t)(e >> 32); }

typedef uint32_t vfx_component;
#define VFX_COMPONENT_NONE UINT32_MAX
#define VFX_MAX_COMPONENTS 256
#define VFX_MAX_TABLE_COMPONENTS 32
#define VFX_MAX_QUERY_TERMS 16

typedef struct vfx_component_desc {
    const char *name;   /* unique, e.g. "vfx.particle.position" */
    uint32_t size;      /* bytes per entity (all fields); 0 = tag component (no column) */
    uint32_t align;     /* 0 -> natural alignment up to 16 */
    uint32_t fields;    /* 0/1 -> one column; n -> n columns of size/n bytes each (SoA) */
} vfx_component_desc;

typedef enum vfx_phase {
    VFX_PHASE_SIMULATE = 0,
    VFX_PHASE_PRE_RENDER = 1,
    VFX_PHASE_RENDER = 2,
    VFX_PHASE_POST_RENDER = 3,
    VFX_PHASE_COUNT = 4,
} vfx_phase;

typedef struct vfx_world vfx_world;

typedef struct vfx_system_ctx {
    double time;
    float dt;
    void *user;
    const char *name;
} vfx_system_ctx;

typedef vfx_result (*vfx_system_fn)(vfx_world *world, const vfx_system_ctx *ctx);

typedef struct vfx_system_desc {
    const char *name;
    vfx_phase phase;
    const vfx_component *reads;  uint32_t read_count;   /* declared, checked registered */
    const vfx_component *writes; uint32_t write_count;
    vfx_system_fn fn;
    void *user;
} vfx_system_desc;

typedef struct vfx_world_desc {
    vfx_logger logger;
    /* Called after each system with its CPU time (the profiler hooks in here). */
    void (*on_system_done)(void *user, const char *system, vfx_phase phase, double cpu_ms);
    void *on_system_user;
} vfx_world_desc;

/* Creates an empty world; NULL desc = defaults. Returns NULL only when out of memory. */
vfx_world *vfx_world_create(const vfx_world_desc *desc);
/* Destroys the world, every table and column. NULL allowed. */
void vfx_world_destroy(vfx_world *world);
/* The last error message of this world ("" when none). */
const char *vfx_world_last_error(const vfx_world *world);

/* Registers a component; a second registration of the same name is refused. */
vfx_result vfx_world_register(vfx_world *world, const vfx_component_desc *desc, vfx_component *out);
/* Component id by name, or VFX_COMPONENT_NONE. */
vfx_component vfx_world_lookup(const vfx_world *world, const char *name);
/* Descriptor of a registered component, or NULL. */
const vfx_component_desc *vfx_world_component_desc(const vfx_world *world, vfx_component c);

/* Spawns `count` entities with the given components (zero-initialised) into one table;
 * ids written to out_ids when not NULL. count 0 is a no-op. */
vfx_result vfx_world_spawn(vfx_world *world, uint32_t count, const vfx_component *comps,
                           uint32_t comp_count, vfx_entity *out_ids);
/* Removes an entity; its id becomes stale (vfx_world_alive false), its index is reused with
 * a new generation. A stale or null id is refused (VFX_ERR_NOT_FOUND). */
vfx_result vfx_world_despawn(vfx_world *world, vfx_entity e);
/* True when `e` is a live entity of this world. */
bool vfx_world_alive(const vfx_world *world, vfx_entity e);
/* Number of live entities. */
uint32_t vfx_world_entity_count(const vfx_world *world);
/* Adds a (zeroed) component to an entity, moving it to another table. Adding one it has is ok. */
vfx_result vfx_world_add(vfx_world *world, vfx_entity e, vfx_component c);
/* Removes a component from an entity. Removing one it lacks is ok. */
vfx_result vfx_world_remove(vfx_world *world, vfx_entity e, vfx_component c);
/* True when the live entity has the component. */
bool vfx_world_has(const vfx_world *world, vfx_entity e, vfx_component c);
/* Pointer to field `field` of component c of entity e (field 0 for single-field components);
 * NULL when e is not alive, lacks c, or c is a tag. Valid until the next structural change. */
void *vfx_world_get(vfx_world *world, vfx_entity e, vfx_component c, uint32_t field);

/* Query iteration over every non-empty table holding all the terms, in table creation order:
 *   vfx_query_iter it = vfx_query_begin(world, terms, n);
 *   while (vfx_query_next(&it)) { float *x = vfx_query_column(&it, pos, 0); ... it.rows ... } */
typedef struct vfx_query_iter {
    vfx_world *world;
    vfx_component terms[VFX_MAX_QUERY_TERMS];
    uint32_t term_count;
    uint32_t next_table;
    uint32_t table;       /* current table index */
    uint32_t rows;        /* entities in the current table */
    const vfx_entity *entities;
} vfx_query_iter;

/* Starts a query; more than VFX_MAX_QUERY_TERMS terms are cut (and logged). */
vfx_query_iter vfx_query_begin(vfx_world *world, const vfx_component *terms, uint32_t term_count);
/* Advances to the next matching non-empty table; false at the end. */
bool vfx_query_next(vfx_query_iter *it);
/* Column (field `field`) of component c in the current table, or NULL when the table lacks c. */
void *vfx_query_column(const vfx_query_iter *it, vfx_component c, uint32_t field);
/* Total entities matching a query. */
uint32_t vfx_query_count(vfx_world *world, const vfx_component *terms, uint32_t term_count);
/* Increments each time a table's content may have changed (structural change or a system that
 * declared a write to one of its components ran): hosts use it as an upload revision. */
uint64_t vfx_world_table_revision(const vfx_world *world, uint32_t table);

/* Permutes the rows of a table: new row i takes old row perm[i] (a permutation of
 * 0..rows-1, checked). Entity records follow. For simulations that sort for locality. */
vfx_result vfx_world_table_permute(vfx_world *world, uint32_t table, const uint32_t *perm);

/* Registers a system; order is phase first, then registration order (deterministic). */
vfx_result vfx_world_add_system(vfx_world *world, const vfx_system_desc *desc);
/* Runs every system of one phase in order; stops at the first error (message names it). */
vfx_result vfx_world_run_phase(vfx_world *world, vfx_phase phase, double time, float dt);
/* Runs all phases in order. */
vfx_result vfx_world_progress(vfx_world *world, double time, float dt);
/* Number of systems and the name of system i in execution order (for tests and tools). */
uint32_t vfx_world_system_count(const vfx_world *world);
const char *vfx_world_system_name(const vfx_world *world, uint32_t i);

#endif
