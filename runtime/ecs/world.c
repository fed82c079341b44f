/* world.c — archetype ECS. Tables are found by their sorted component set; rows move between
 * tables on add/remove; swap-remove keeps every column dense. */
#include "ecs/world.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>


#define COLUMN_ALIGN 64u

typedef struct component_info {
    rt_component_desc desc;
    char name[64];
    uint32_t field_size; /* size / fields */
} component_info;

typedef struct table {
    uint32_t comp_count;
    rt_component comps[RT_MAX_TABLE_COMPONENTS]; /* sorted ascending */
    uint32_t column_base[RT_MAX_TABLE_COMPONENTS]; /* first column index of comps[i] */
    uint32_t column_count;
    void **columns;           /* column_count arrays */
    uint32_t *column_size;    /* element size of each column */
    rt_entity *entities;
    uint32_t rows, capacity;
    uint64_t revision;
} table;

typedef struct entity_record {
    uint32_t generation; /* current generation of this index; odd use: alive flag below */
    uint32_t table;
    uint32_t row;
    bool alive;
} entity_record;

typedef struct system_entry {
    rt_system_desc desc;
    char name[64];
    rt_component reads[RT_MAX_QUERY_TERMS], writes[RT_MAX_QUERY_TERMS];
    uint32_t order; /* registration order */
} system_entry;

struct rt_world {
    rt_world_desc desc;
    component_info comps[RT_MAX_COMPONENTS];
    uint32_t comp_count;
    table *tables;
    uint32_t table_count, table_capacity;
    entity_record *records;
    uint32_t record_count, record_capacity;
    uint32_t *free_indices;
    uint32_t free_count, free_capacity;
    uint32_t alive_count;
    system_entry *systems;
    uint32_t system_count, system_capacity;
    char error[256];
};

vfx_result rt_world_fail(rt_world *w, vfx_result r, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->error, sizeof w->error, fmt, ap);
    va_end(ap);
    rt_logf(&w->desc.logger, VFX_LOG_ERROR, "ecs: %s", w->error);
    return r;
}

static void *aligned_zalloc(size_t bytes)
{
    size_t rounded = (bytes + COLUMN_ALIGN - 1) / COLUMN_ALIGN * COLUMN_ALIGN;
    if (rounded == 0)
        rounded = COLUMN_ALIGN;
    void *p = aligned_alloc(COLUMN_ALIGN, rounded);
    if (p)
        memset(p, 0, rounded);
    return p;
}

/* Grows a plain array geometrically; keeps the old one on failure. */
static bool grow(void **arr, uint32_t *cap, uint32_t need, size_t elem)
{
    if (need <= *cap)
        return true;
    uint64_t n = *cap ? *cap : 16;
    while (n < need)
        n *= 2;
    if (n > UINT32_MAX || n * elem > SIZE_MAX / 2)
        return false;
    void *p = realloc(*arr, (size_t)n * elem);
    if (!p)
        return false;
    *arr = p;
    *cap = (uint32_t)n;
    return true;
}

rt_world *rt_world_create(const rt_world_desc *desc)
{
    rt_world *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    if (desc)
        w->desc = *desc;
    return w;
}

static void table_free(table *t)
{
    for (uint32_t i = 0; i < t->column_count; ++i)
        free(t->columns[i]);
    free(t->columns);
    free(t->column_size);
    free(t->entities);
}

void rt_world_destroy(rt_world *w)
{
    if (!w)
        return;
    for (uint32_t i = 0; i < w->table_count; ++i)
        table_free(&w->tables[i]);
    free(w->tables);
    free(w->records);
    free(w->free_indices);
    free(w->systems);
    free(w);
}

const char *rt_world_last_error(const rt_world *w) { return w ? w->error : "no world"; }

vfx_result rt_world_register(rt_world *w, const rt_component_desc *desc, rt_component *out)
{
    if (!w || !desc || !desc->name || !desc->name[0])
        return w ? rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "register: component needs a name")
                 : VFX_ERR_INVALID_ARGUMENT;
    if (strlen(desc->name) >= sizeof w->comps[0].name)
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "register: name '%.40s...' longer than %zu",
                          desc->name, sizeof w->comps[0].name - 1);
    if (rt_world_lookup(w, desc->name) != RT_COMPONENT_NONE)
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "register: component '%s' already registered",
                          desc->name);
    if (w->comp_count >= RT_MAX_COMPONENTS)
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "register: more than %d components",
                          RT_MAX_COMPONENTS);
    uint32_t fields = desc->fields ? desc->fields : 1;
    if (desc->size % fields != 0)
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT,
                          "register '%s': size %u is not a multiple of its %u fields", desc->name,
                          desc->size, fields);
    if (desc->align && (desc->align & (desc->align - 1)))
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "register '%s': align %u not a power of two",
                          desc->name, desc->align);
    if (desc->align > COLUMN_ALIGN)
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "register '%s': align %u above %u",
                          desc->name, desc->align, COLUMN_ALIGN);
    component_info *ci = &w->comps[w->comp_count];
    ci->desc = *desc;
    ci->desc.fields = fields;
    snprintf(ci->name, sizeof ci->name, "%s", desc->name);
    ci->desc.name = ci->name;
    ci->field_size = desc->size / fields;
    *out = w->comp_count++;
    return VFX_OK;
}

rt_component rt_world_lookup(const rt_world *w, const char *name)
{
    if (!w || !name)
        return RT_COMPONENT_NONE;
    for (uint32_t i = 0; i < w->comp_count; ++i)
        if (strcmp(w->comps[i].name, name) == 0)
            return i;
    return RT_COMPONENT_NONE;
}

/* ------------------------------------------------------------------------ tables */

static int table_comp_slot(const table *t, rt_component c)
{
    for (uint32_t i = 0; i < t->comp_count; ++i)
        if (t->comps[i] == c)
            return (int)i;
    return -1;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Sorted, de-duplicated copy of a component set; returns its length or -1 on a bad id. */
static int normalize_set(const rt_world *w, const rt_component *in, uint32_t n,
                         rt_component out[RT_MAX_TABLE_COMPONENTS])
{
    if (n > RT_MAX_TABLE_COMPONENTS)
        return -1;
    for (uint32_t i = 0; i < n; ++i) {
        if (in[i] >= w->comp_count)
            return -1;
        out[i] = in[i];
    }
    qsort(out, n, sizeof *out, cmp_u32);
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; ++i)
        if (m == 0 || out[m - 1] != out[i])
            out[m++] = out[i];
    return (int)m;
}

static vfx_result table_find_or_make(rt_world *w, const rt_component *set, uint32_t n,
                                     uint32_t *out)
{
    for (uint32_t i = 0; i < w->table_count; ++i) {
        table *t = &w->tables[i];
        if (t->comp_count == n && memcmp(t->comps, set, n * sizeof *set) == 0) {
            *out = i;
            return VFX_OK;
        }
    }
    if (!grow((void **)&w->tables, &w->table_capacity, w->table_count + 1, sizeof(table)))
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "out of memory making a table");
    table *t = &w->tables[w->table_count];
    memset(t, 0, sizeof *t);
    t->comp_count = n;
    memcpy(t->comps, set, n * sizeof *set);
    uint32_t cols = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const component_info *ci = &w->comps[set[i]];
        t->column_base[i] = cols;
        cols += ci->desc.size ? ci->desc.fields : 0;
    }
    t->column_count = cols;
    t->columns = calloc(cols ? cols : 1, sizeof(void *));
    t->column_size = calloc(cols ? cols : 1, sizeof(uint32_t));
    if (!t->columns || !t->column_size) {
        free(t->columns);
        free(t->column_size);
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "out of memory making a table");
    }
    for (uint32_t i = 0; i < n; ++i) {
        const component_info *ci = &w->comps[set[i]];
        if (!ci->desc.size)
            continue;
        for (uint32_t f = 0; f < ci->desc.fields; ++f)
            t->column_size[t->column_base[i] + f] = ci->field_size;
    }
    *out = w->table_count++;
    return VFX_OK;
}

/* Makes room for `need` rows; columns are reallocated (and so move) only here. */
static vfx_result table_reserve(rt_world *w, table *t, uint32_t need)
{
    if (need <= t->capacity)
        return VFX_OK;
    uint64_t cap = t->capacity ? t->capacity : 64;
    while (cap < need)
        cap *= 2;
    if (cap > UINT32_MAX)
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "table of %u rows too large", need);
    for (uint32_t c = 0; c < t->column_count; ++c) {
        void *p = aligned_zalloc((size_t)cap * t->column_size[c]);
        if (!p)
            return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "out of memory for %llu rows",
                              (unsigned long long)cap);
        if (t->columns[c])
            memcpy(p, t->columns[c], (size_t)t->rows * t->column_size[c]);
        free(t->columns[c]);
        t->columns[c] = p;
    }
    rt_entity *e = realloc(t->entities, (size_t)cap * sizeof *e);
    if (!e)
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "out of memory for %llu rows",
                          (unsigned long long)cap);
    t->entities = e;
    t->capacity = (uint32_t)cap;
    return VFX_OK;
}

/* Removes row r by moving the last row into it; fixes the moved entity's record. */
static void table_swap_remove(rt_world *w, table *t, uint32_t r)
{
    uint32_t last = t->rows - 1;
    if (r != last) {
        for (uint32_t c = 0; c < t->column_count; ++c) {
            uint32_t s = t->column_size[c];
            memcpy((char *)t->columns[c] + (size_t)r * s, (char *)t->columns[c] + (size_t)last * s, s);
        }
        t->entities[r] = t->entities[last];
        w->records[rt_entity_index(t->entities[r])].row = r;
    }
    for (uint32_t c = 0; c < t->column_count; ++c) {
        uint32_t s = t->column_size[c];
        memset((char *)t->columns[c] + (size_t)last * s, 0, s);
    }
    t->rows--;
    t->revision++;
}

/* ---------------------------------------------------------------------- entities */

static vfx_result new_entity(rt_world *w, uint32_t table_index, uint32_t row, rt_entity *out)
{
    uint32_t idx;
    if (w->free_count) {
        idx = w->free_indices[--w->free_count];
    } else {
        if (w->record_count == UINT32_MAX)
            return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "entity index space exhausted");
        if (!grow((void **)&w->records, &w->record_capacity, w->record_count + 1,
                  sizeof(entity_record)))
            return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "out of memory for entity records");
        idx = w->record_count++;
        w->records[idx].generation = 0;
    }
    entity_record *rec = &w->records[idx];
    rec->generation++;
    if (rec->generation == 0) /* wrapped: skip 0 so an id is never null */
        rec->generation = 1;
    rec->alive = true;
    rec->table = table_index;
    rec->row = row;
    w->alive_count++;
    *out = ((rt_entity)rec->generation << 32) | idx;
    return VFX_OK;
}

vfx_result rt_world_spawn(rt_world *w, uint32_t count, const rt_component *comps,
                           uint32_t comp_count, rt_entity *out_ids)
{
    if (!w)
        return VFX_ERR_INVALID_ARGUMENT;
    if (count == 0)
        return VFX_OK;
    if (comp_count && !comps)
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "spawn: NULL component list");
    rt_component set[RT_MAX_TABLE_COMPONENTS];
    int n = normalize_set(w, comps, comp_count, set);
    if (n < 0)
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT,
                          "spawn: unknown component id or more than %d components",
                          RT_MAX_TABLE_COMPONENTS);
    if ((uint64_t)w->alive_count + count > UINT32_MAX - 1)
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "spawn: %u entities exceed the id space", count);
    uint32_t ti;
    vfx_result r = table_find_or_make(w, set, (uint32_t)n, &ti);
    if (r)
        return r;
    table *t = &w->tables[ti];
    if ((uint64_t)t->rows + count > UINT32_MAX)
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "spawn: table would exceed 2^32 rows");
    if ((r = table_reserve(w, t, t->rows + count)))
        return r;
    if (!grow((void **)&w->records, &w->record_capacity, w->record_count + count,
              sizeof(entity_record)))
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "spawn: out of memory for %u records", count);
    for (uint32_t i = 0; i < count; ++i) {
        rt_entity e = RT_ENTITY_NULL;
        if ((r = new_entity(w, ti, t->rows, &e)))
            return r;
        t->entities[t->rows++] = e;
        if (out_ids)
            out_ids[i] = e;
    }
    t->revision++;
    return VFX_OK;
}

static entity_record *live_record(const rt_world *w, rt_entity e)
{
    uint32_t idx = rt_entity_index(e);
    if (e == RT_ENTITY_NULL || idx >= w->record_count)
        return NULL;
    entity_record *rec = &w->records[idx];
    if (!rec->alive || rec->generation != rt_entity_generation(e))
        return NULL;
    return rec;
}

bool rt_world_alive(const rt_world *w, rt_entity e) { return w && live_record(w, e) != NULL; }

uint32_t rt_world_entity_count(const rt_world *w) { return w ? w->alive_count : 0; }

vfx_result rt_world_despawn(rt_world *w, rt_entity e)
{
    if (!w)
        return VFX_ERR_INVALID_ARGUMENT;
    entity_record *rec = live_record(w, e);
    if (!rec)
        return rt_world_fail(w, VFX_ERR_NOT_FOUND, "despawn: entity %u (generation %u) is not alive",
                          rt_entity_index(e), rt_entity_generation(e));
    table_swap_remove(w, &w->tables[rec->table], rec->row);
    rec->alive = false;
    if (!grow((void **)&w->free_indices, &w->free_capacity, w->free_count + 1, sizeof(uint32_t)))
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "despawn: out of memory for the free list");
    w->free_indices[w->free_count++] = rt_entity_index(e);
    w->alive_count--;
    return VFX_OK;
}

bool rt_world_has(const rt_world *w, rt_entity e, rt_component c)
{
    entity_record *rec = w ? live_record(w, e) : NULL;
    return rec && table_comp_slot(&w->tables[rec->table], c) >= 0;
}

void *rt_world_get(rt_world *w, rt_entity e, rt_component c, uint32_t field)
{
    entity_record *rec = w ? live_record(w, e) : NULL;
    if (!rec)
        return NULL;
    table *t = &w->tables[rec->table];
    int slot = table_comp_slot(t, c);
    if (slot < 0 || !w->comps[c].desc.size || field >= w->comps[c].desc.fields)
        return NULL;
    uint32_t col = t->column_base[slot] + field;
    return (char *)t->columns[col] + (size_t)rec->row * t->column_size[col];
}

/* Moves entity e to the table with component set `set`, copying shared columns. */
static vfx_result move_entity(rt_world *w, entity_record *rec, rt_entity e,
                              const rt_component *set, uint32_t n)
{
    uint32_t dst_i;
    vfx_result r = table_find_or_make(w, set, n, &dst_i);
    if (r)
        return r;
    table *dst = &w->tables[dst_i];
    if ((r = table_reserve(w, dst, dst->rows + 1)))
        return r;
    table *src = &w->tables[rec->table]; /* after table_find_or_make: tables may have moved */
    uint32_t row = dst->rows++;
    dst->entities[row] = e;
    for (uint32_t i = 0; i < dst->comp_count; ++i) {
        int s = table_comp_slot(src, dst->comps[i]);
        const component_info *ci = &w->comps[dst->comps[i]];
        if (s < 0 || !ci->desc.size)
            continue;
        for (uint32_t f = 0; f < ci->desc.fields; ++f) {
            uint32_t dc = dst->column_base[i] + f, sc = src->column_base[s] + f;
            memcpy((char *)dst->columns[dc] + (size_t)row * ci->field_size,
                   (char *)src->columns[sc] + (size_t)rec->row * ci->field_size, ci->field_size);
        }
    }
    table_swap_remove(w, src, rec->row);
    rec->table = dst_i;
    rec->row = row;
    dst->revision++;
    return VFX_OK;
}

vfx_result rt_world_add(rt_world *w, rt_entity e, rt_component c)
{
    if (!w)
        return VFX_ERR_INVALID_ARGUMENT;
    entity_record *rec = live_record(w, e);
    if (!rec)
        return rt_world_fail(w, VFX_ERR_NOT_FOUND, "add: entity %u is not alive", rt_entity_index(e));
    if (c >= w->comp_count)
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "add: unknown component id %u", c);
    const table *t = &w->tables[rec->table];
    if (table_comp_slot(t, c) >= 0)
        return VFX_OK;
    if (t->comp_count >= RT_MAX_TABLE_COMPONENTS)
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "add: entity already has %d components",
                          RT_MAX_TABLE_COMPONENTS);
    rt_component set[RT_MAX_TABLE_COMPONENTS];
    memcpy(set, t->comps, t->comp_count * sizeof *set);
    set[t->comp_count] = c;
    rt_component sorted[RT_MAX_TABLE_COMPONENTS];
    int n = normalize_set(w, set, t->comp_count + 1, sorted);
    return move_entity(w, rec, e, sorted, (uint32_t)n);
}

vfx_result rt_world_remove(rt_world *w, rt_entity e, rt_component c)
{
    if (!w)
        return VFX_ERR_INVALID_ARGUMENT;
    entity_record *rec = live_record(w, e);
    if (!rec)
        return rt_world_fail(w, VFX_ERR_NOT_FOUND, "remove: entity %u is not alive",
                          rt_entity_index(e));
    const table *t = &w->tables[rec->table];
    if (table_comp_slot(t, c) < 0)
        return VFX_OK;
    rt_component set[RT_MAX_TABLE_COMPONENTS];
    uint32_t n = 0;
    for (uint32_t i = 0; i < t->comp_count; ++i)
        if (t->comps[i] != c)
            set[n++] = t->comps[i];
    return move_entity(w, rec, e, set, n);
}

/* ----------------------------------------------------------------------- queries */

rt_query_iter rt_query_begin(rt_world *w, const rt_component *terms, uint32_t term_count)
{
    rt_query_iter it;
    memset(&it, 0, sizeof it);
    it.world = w;
    if (term_count > RT_MAX_QUERY_TERMS) {
        if (w)
            rt_logf(&w->desc.logger, VFX_LOG_WARN, "ecs: query of %u terms cut to %d", term_count,
                     RT_MAX_QUERY_TERMS);
        term_count = RT_MAX_QUERY_TERMS;
    }
    if (terms)
        memcpy(it.terms, terms, term_count * sizeof *terms);
    it.term_count = terms ? term_count : 0;
    it.table = UINT32_MAX;
    return it;
}

static bool table_matches(const table *t, const rt_component *terms, uint32_t n)
{
    for (uint32_t i = 0; i < n; ++i)
        if (table_comp_slot(t, terms[i]) < 0)
            return false;
    return true;
}

bool rt_query_next(rt_query_iter *it)
{
    rt_world *w = it->world;
    if (!w)
        return false;
    while (it->next_table < w->table_count) {
        uint32_t i = it->next_table++;
        table *t = &w->tables[i];
        if (t->rows && table_matches(t, it->terms, it->term_count)) {
            it->table = i;
            it->rows = t->rows;
            it->entities = t->entities;
            return true;
        }
    }
    it->rows = 0;
    it->entities = NULL;
    return false;
}

void *rt_query_column(const rt_query_iter *it, rt_component c, uint32_t field)
{
    rt_world *w = it->world;
    if (!w || it->table >= w->table_count || c >= w->comp_count)
        return NULL;
    table *t = &w->tables[it->table];
    int slot = table_comp_slot(t, c);
    if (slot < 0 || !w->comps[c].desc.size || field >= w->comps[c].desc.fields)
        return NULL;
    return t->columns[t->column_base[slot] + field];
}

uint32_t rt_query_count(rt_world *w, const rt_component *terms, uint32_t term_count)
{
    uint32_t total = 0;
    rt_query_iter it = rt_query_begin(w, terms, term_count);
    while (rt_query_next(&it))
        total += it.rows;
    return total;
}

uint64_t rt_world_table_revision(const rt_world *w, uint32_t table_index)
{
    return (w && table_index < w->table_count) ? w->tables[table_index].revision : 0;
}

vfx_result rt_world_table_permute(rt_world *w, uint32_t ti, const uint32_t *perm)
{
    if (!w || ti >= w->table_count || !perm)
        return w ? rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "permute: bad table %u or NULL perm", ti)
                 : VFX_ERR_INVALID_ARGUMENT;
    table *t = &w->tables[ti];
    if (t->rows == 0)
        return VFX_OK;
    /* Check it is a permutation before touching anything. */
    uint8_t *seen = calloc(t->rows, 1);
    if (!seen)
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "permute: out of memory");
    for (uint32_t i = 0; i < t->rows; ++i) {
        if (perm[i] >= t->rows || seen[perm[i]]) {
            free(seen);
            return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT,
                              "permute: perm[%u] = %u is out of range or repeated", i, perm[i]);
        }
        seen[perm[i]] = 1;
    }
    free(seen);
    size_t max_size = sizeof(rt_entity);
    for (uint32_t c = 0; c < t->column_count; ++c)
        if (t->column_size[c] > max_size)
            max_size = t->column_size[c];
    char *tmp = malloc((size_t)t->rows * max_size);
    if (!tmp)
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "permute: out of memory");
    for (uint32_t c = 0; c < t->column_count; ++c) {
        uint32_t s = t->column_size[c];
        const char *src = t->columns[c];
        for (uint32_t i = 0; i < t->rows; ++i)
            memcpy(tmp + (size_t)i * s, src + (size_t)perm[i] * s, s);
        memcpy(t->columns[c], tmp, (size_t)t->rows * s);
    }
    rt_entity *ent = (rt_entity *)tmp;
    for (uint32_t i = 0; i < t->rows; ++i)
        ent[i] = t->entities[perm[i]];
    memcpy(t->entities, ent, (size_t)t->rows * sizeof *ent);
    for (uint32_t i = 0; i < t->rows; ++i)
        w->records[rt_entity_index(t->entities[i])].row = i;
    free(tmp);
    t->revision++;
    return VFX_OK;
}

/* ----------------------------------------------------------------------- systems */

vfx_result rt_world_add_system(rt_world *w, const rt_system_desc *d)
{
    if (!w || !d || !d->fn)
        return w ? rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "add_system: NULL function")
                 : VFX_ERR_INVALID_ARGUMENT;
    const char *name = d->name ? d->name : "(unnamed)";
    if ((unsigned)d->phase >= RT_PHASE_COUNT)
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "add_system '%s': phase %d out of range",
                          name, (int)d->phase);
    if (d->read_count > RT_MAX_QUERY_TERMS || d->write_count > RT_MAX_QUERY_TERMS)
        return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT, "add_system '%s': more than %d reads/writes",
                          name, RT_MAX_QUERY_TERMS);
    for (uint32_t i = 0; i < d->read_count; ++i)
        if (d->reads[i] >= w->comp_count)
            return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT,
                              "add_system '%s': reads unregistered component %u", name, d->reads[i]);
    for (uint32_t i = 0; i < d->write_count; ++i)
        if (d->writes[i] >= w->comp_count)
            return rt_world_fail(w, VFX_ERR_INVALID_ARGUMENT,
                              "add_system '%s': writes unregistered component %u", name,
                              d->writes[i]);
    if (!grow((void **)&w->systems, &w->system_capacity, w->system_count + 1, sizeof(system_entry)))
        return rt_world_fail(w, VFX_ERR_OUT_OF_MEMORY, "add_system: out of memory");
    system_entry *s = &w->systems[w->system_count];
    memset(s, 0, sizeof *s);
    s->desc = *d;
    snprintf(s->name, sizeof s->name, "%s", name);
    s->desc.name = s->name;
    if (d->read_count)
        memcpy(s->reads, d->reads, d->read_count * sizeof *d->reads);
    if (d->write_count)
        memcpy(s->writes, d->writes, d->write_count * sizeof *d->writes);
    s->desc.reads = s->reads;
    s->desc.writes = s->writes;
    s->order = w->system_count;
    w->system_count++;
    /* Stable insertion by phase keeps registration order inside a phase. */
    for (uint32_t i = w->system_count - 1; i > 0; --i) {
        system_entry *a = &w->systems[i - 1], *b = &w->systems[i];
        if (a->desc.phase <= b->desc.phase)
            break;
        system_entry tmp = *a;
        *a = *b;
        *b = tmp;
    }
    /* Fix the internal pointers after moving entries. */
    for (uint32_t i = 0; i < w->system_count; ++i) {
        w->systems[i].desc.name = w->systems[i].name;
        w->systems[i].desc.reads = w->systems[i].reads;
        w->systems[i].desc.writes = w->systems[i].writes;
    }
    return VFX_OK;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

vfx_result rt_world_run_phase(rt_world *w, rt_phase phase, double time, float dt)
{
    if (!w || (unsigned)phase >= RT_PHASE_COUNT)
        return VFX_ERR_INVALID_ARGUMENT;
    for (uint32_t i = 0; i < w->system_count; ++i) {
        system_entry *s = &w->systems[i];
        if (s->desc.phase != phase)
            continue;
        rt_system_ctx ctx = {time, dt, s->desc.user, s->name};
        double t0 = now_ms();
        vfx_result r = s->desc.fn(w, &ctx);
        double ms = now_ms() - t0;
        if (w->desc.on_system_done)
            w->desc.on_system_done(w->desc.on_system_user, s->name, phase, ms);
        /* A declared write means the columns may have changed: bump the revisions so hosts
         * re-upload exactly the tables that hold written components. */
        for (uint32_t k = 0; k < s->desc.write_count; ++k)
            for (uint32_t t = 0; t < w->table_count; ++t)
                if (table_comp_slot(&w->tables[t], s->writes[k]) >= 0)
                    w->tables[t].revision++;
        if (r != VFX_OK) {
            char msg[sizeof w->error];
            snprintf(msg, sizeof msg, "%s", w->error);
            return rt_world_fail(w, r, "system '%s' failed: %s%s%s", s->name, vfx_result_name(r),
                              msg[0] ? ": " : "", msg);
        }
    }
    return VFX_OK;
}

vfx_result rt_world_progress(rt_world *w, double time, float dt)
{
    for (int p = 0; p < RT_PHASE_COUNT; ++p) {
        vfx_result r = rt_world_run_phase(w, (rt_phase)p, time, dt);
        if (r)
            return r;
    }
    return VFX_OK;
}

uint32_t rt_world_system_count(const rt_world *w) { return w ? w->system_count : 0; }

const char *rt_world_system_name(const rt_world *w, uint32_t i)
{
    return (w && i < w->system_count) ? w->systems[i].name : NULL;
}

uint32_t rt_world_table_component_count(const rt_world *w, uint32_t ti)
{
    return w && ti < w->table_count ? w->tables[ti].comp_count : 0;
}
