/* world.h — the ECS world: generational entity ids, components registered at run time,
 * archetype tables stored as structure of arrays, queries and a phase scheduler.
 *
 * Storage: entities with the same set of components share a table; each component is one
 * contiguous column in that table, and a component declared with fields > 1 is stored as one
 * contiguous column per field (x[], y[], z[]), so a whole column goes to the GPU in one call
 * with no copy. Columns are 64-byte aligned. A column pointer stays valid until the next
 * structural change (spawn, despawn, add, remove, reorder) of that table.
 * No global state: everything lives in a rt_world. Not thread-safe; systems run in order. */
#ifndef RT_ECS_WORLD_H
#define RT_ECS_WORLD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "core/log.h"

/* Entity id: low 32 bits index, high 32 bits generation (>= 1). 0 is never a live entity. */
typedef uint64_t rt_entity;
#define RT_ENTITY_NULL ((rt_entity)0)
static inline uint32_t rt_entity_index(rt_entity e) { return (uint32_t)e; }
static inline uint32_t rt_entity_generation(rt_entity e) { return (uint32_t)(e >> 32); }

typedef uint32_t rt_component;
#define RT_COMPONENT_NONE UINT32_MAX
#define RT_MAX_COMPONENTS 256
#define RT_MAX_TABLE_COMPONENTS 32
#define RT_MAX_QUERY_TERMS 16

typedef struct rt_component_desc {
    const char *name;   /* unique, e.g. "vfx.particle.position" */
    uint32_t size;      /* bytes per entity (all fields); 0 = tag component (no column) */
    uint32_t align;     /* 0 -> natural alignment up to 16 */
    uint32_t fields;    /* 0/1 -> one column; n -> n columns of size/n bytes each (SoA) */
} rt_component_desc;

typedef enum rt_phase {
    RT_PHASE_SIMULATE = 0,
    RT_PHASE_PRE_RENDER = 1,
    RT_PHASE_RENDER = 2,
    RT_PHASE_POST_RENDER = 3,
    RT_PHASE_COUNT = 4,
} rt_phase;

typedef struct rt_world rt_world;

typedef struct rt_system_ctx {
    double time;
    float dt;
    void *user;
    const char *name;
} rt_system_ctx;

typedef vfx_result (*rt_system_fn)(rt_world *world, const rt_system_ctx *ctx);

typedef struct rt_system_desc {
    const char *name;
    rt_phase phase;
    const rt_component *reads;  uint32_t read_count;   /* declared, checked registered */
    const rt_component *writes; uint32_t write_count;
    rt_system_fn fn;
    void *user;
} rt_system_desc;

typedef struct rt_world_desc {
    rt_logger logger;
    /* Called after each system with its CPU time (the profiler hooks in here). */
    void (*on_system_done)(void *user, const char *system, rt_phase phase, double cpu_ms);
    void *on_system_user;
} rt_world_desc;

/* Creates an empty world; NULL desc = defaults. Returns NULL only when out of memory. */
rt_world *rt_world_create(const rt_world_desc *desc);
/* Destroys the world, every table and column. NULL allowed. */
void rt_world_destroy(rt_world *world);
/* The last error message of this world ("" when none). */
const char *rt_world_last_error(const rt_world *world);

/* Registers a component; a second registration of the same name is refused. */
vfx_result rt_world_register(rt_world *world, const rt_component_desc *desc, rt_component *out);
/* Component id by name, or RT_COMPONENT_NONE. */
rt_component rt_world_lookup(const rt_world *world, const char *name);

/* Spawns `count` entities with the given components (zero-initialised) into one table;
 * ids written to out_ids when not NULL. count 0 is a no-op. */
vfx_result rt_world_spawn(rt_world *world, uint32_t count, const rt_component *comps,
                           uint32_t comp_count, rt_entity *out_ids);
/* Removes an entity; its id becomes stale (rt_world_alive false), its index is reused with
 * a new generation. A stale or null id is refused (VFX_ERR_NOT_FOUND). */
vfx_result rt_world_despawn(rt_world *world, rt_entity e);
/* True when `e` is a live entity of this world. */
bool rt_world_alive(const rt_world *world, rt_entity e);
/* Number of live entities. */
uint32_t rt_world_entity_count(const rt_world *world);
/* Adds a (zeroed) component to an entity, moving it to another table. Adding one it has is ok. */
vfx_result rt_world_add(rt_world *world, rt_entity e, rt_component c);
/* Removes a component from an entity. Removing one it lacks is ok. */
vfx_result rt_world_remove(rt_world *world, rt_entity e, rt_component c);
/* True when the live entity has the component. */
bool rt_world_has(const rt_world *world, rt_entity e, rt_component c);
/* Pointer to field `field` of component c of entity e (field 0 for single-field components);
 * NULL when e is not alive, lacks c, or c is a tag. Valid until the next structural change. */
void *rt_world_get(rt_world *world, rt_entity e, rt_component c, uint32_t field);

/* Query iteration over every non-empty table holding all the terms, in table creation order:
 *   rt_query_iter it = rt_query_begin(world, terms, n);
 *   while (rt_query_next(&it)) { float *x = rt_query_column(&it, pos, 0); ... it.rows ... } */
typedef struct rt_query_iter {
    rt_world *world;
    rt_component terms[RT_MAX_QUERY_TERMS];
    uint32_t term_count;
    uint32_t next_table;
    uint32_t table;       /* current table index */
    uint32_t rows;        /* entities in the current table */
    const rt_entity *entities;
} rt_query_iter;

/* Starts a query; more than RT_MAX_QUERY_TERMS terms are cut (and logged). */
rt_query_iter rt_query_begin(rt_world *world, const rt_component *terms, uint32_t term_count);
/* Advances to the next matching non-empty table; false at the end. */
bool rt_query_next(rt_query_iter *it);
/* Column (field `field`) of component c in the current table, or NULL when the table lacks c. */
void *rt_query_column(const rt_query_iter *it, rt_component c, uint32_t field);
/* Total entities matching a query. */
uint32_t rt_query_count(rt_world *world, const rt_component *terms, uint32_t term_count);
/* Increments each time a table's content may have changed (structural change or a system that
 * declared a write to one of its components ran): hosts use it as an upload revision. */
uint64_t rt_world_table_revision(const rt_world *world, uint32_t table);
/* Number of components of a table (0 for an index out of range). */
uint32_t rt_world_table_component_count(const rt_world *world, uint32_t table);
/* Records an error on the world (rt_world_last_error, logged) and returns r; for modules built
 * on the world, such as ecs/particles.c. */
vfx_result rt_world_fail(rt_world *world, vfx_result r, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Permutes the rows of a table: new row i takes old row perm[i] (a permutation of
 * 0..rows-1, checked). Entity records follow. For simulations that sort for locality. */
vfx_result rt_world_table_permute(rt_world *world, uint32_t table, const uint32_t *perm);

/* Registers a system; order is phase first, then registration order (deterministic). */
vfx_result rt_world_add_system(rt_world *world, const rt_system_desc *desc);
/* Runs every system of one phase in order; stops at the first error (message names it). */
vfx_result rt_world_run_phase(rt_world *world, rt_phase phase, double time, float dt);
/* Runs all phases in order. */
vfx_result rt_world_progress(rt_world *world, double time, float dt);
/* Number of systems and the name of system i in execution order (for tests and tools). */
uint32_t rt_world_system_count(const rt_world *world);
const char *rt_world_system_name(const rt_world *world, uint32_t i);

#endif
