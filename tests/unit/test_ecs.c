/* ECS: ids, generations and reuse, SoA column layout and stability, queries, system order. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "ecs/effects.h"
#include "ecs/particles.h"
#include "ecs/world.h"
#include "test_util.h"

static rt_world *make_world(test_log *log)
{
    rt_world_desc d = {.logger = {test_log_fn, log}};
    rt_world *w = rt_world_create(&d);
    assert_non_null(w);
    return w;
}

static void test_ids_and_reuse(void **state)
{
    (void)state;
    test_log log = {0};
    rt_world *w = make_world(&log);
    rt_component pos;
    assert_int_equal(rt_world_register(w, &(rt_component_desc){"pos", 12, 4, 3}, &pos), VFX_OK);
    rt_entity e[3];
    assert_int_equal(rt_world_spawn(w, 3, &pos, 1, e), VFX_OK);
    assert_true(rt_world_alive(w, e[1]));
    assert_int_equal(rt_world_despawn(w, e[1]), VFX_OK);
    assert_false(rt_world_alive(w, e[1]));
    /* a stale id is refused with a message, never silently accepted */
    assert_int_equal(rt_world_despawn(w, e[1]), VFX_ERR_NOT_FOUND);
    assert_non_null(strstr(rt_world_last_error(w), "despawn: entity"));
    rt_entity again;
    assert_int_equal(rt_world_spawn(w, 1, &pos, 1, &again), VFX_OK);
    /* index reused, generation bumped: the old id stays dead */
    assert_int_equal(rt_entity_index(again), rt_entity_index(e[1]));
    assert_int_not_equal(rt_entity_generation(again), rt_entity_generation(e[1]));
    assert_false(rt_world_alive(w, e[1]));
    assert_true(rt_world_alive(w, again));
    assert_false(rt_world_alive(w, RT_ENTITY_NULL));
    assert_int_equal(rt_world_entity_count(w), 3);
    rt_world_destroy(w);
}

static void test_register_errors(void **state)
{
    (void)state;
    test_log log = {0};
    rt_world *w = make_world(&log);
    rt_component c;
    assert_int_equal(rt_world_register(w, &(rt_component_desc){"a", 4, 4, 1}, &c), VFX_OK);
    assert_int_equal(rt_world_register(w, &(rt_component_desc){"a", 4, 4, 1}, &c), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(log.last, "component 'a'"));
    assert_int_equal(rt_world_register(w, &(rt_component_desc){"b", 10, 4, 3}, &c), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(log.last, "register 'b': size 10"));
    assert_int_equal(rt_world_register(w, &(rt_component_desc){"c", 4, 3, 1}, &c), VFX_ERR_INVALID_ARGUMENT);
    assert_int_equal(rt_world_register(w, &(rt_component_desc){NULL, 4, 4, 1}, &c), VFX_ERR_INVALID_ARGUMENT);
    /* unknown component ids are refused at spawn */
    rt_component bad = 77;
    assert_int_equal(rt_world_spawn(w, 1, &bad, 1, NULL), VFX_ERR_INVALID_ARGUMENT);
    rt_world_destroy(w);
}

static void test_soa_columns(void **state)
{
    (void)state;
    test_log log = {0};
    rt_world *w = make_world(&log);
    rt_particle_components pc;
    assert_int_equal(rt_particles_register(w, &pc), VFX_OK);
    enum { N = 1000 };
    float x[N], y[N], z[N];
    for (int i = 0; i < N; ++i)
        x[i] = (float)i, y[i] = (float)(2 * i), z[i] = (float)(-i);
    assert_int_equal(rt_particles_spawn(w, &pc, N, x, y, z, false), VFX_OK);
    rt_query_iter it = rt_query_begin(w, &pc.position, 1);
    assert_true(rt_query_next(&it));
    assert_int_equal(it.rows, N);
    float *cx = rt_query_column(&it, pc.position, 0);
    float *cy = rt_query_column(&it, pc.position, 1);
    float *cz = rt_query_column(&it, pc.position, 2);
    /* one contiguous, aligned column per field: the GPU can take it in one upload */
    assert_int_equal((uintptr_t)cx % 64, 0);
    for (int i = 0; i < N; ++i) {
        assert_true(cx[i] == x[i] && cy[i] == y[i] && cz[i] == z[i]);
    }
    assert_null(rt_query_column(&it, pc.radius, 0)); /* not in this table */
    assert_null(rt_query_column(&it, pc.position, 3)); /* no such field */
    assert_false(rt_query_next(&it));
    /* NaN positions are refused, naming the particle */
    y[17] = NAN;
    assert_int_equal(rt_particles_spawn(w, &pc, N, x, y, z, false), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(log.last, "particle 17"));
    rt_world_destroy(w);
}

static void test_column_stability_and_moves(void **state)
{
    (void)state;
    test_log log = {0};
    rt_world *w = make_world(&log);
    rt_component a, b, tag;
    assert_int_equal(rt_world_register(w, &(rt_component_desc){"a", 4, 4, 1}, &a), VFX_OK);
    assert_int_equal(rt_world_register(w, &(rt_component_desc){"b", 8, 8, 1}, &b), VFX_OK);
    assert_int_equal(rt_world_register(w, &(rt_component_desc){"tag", 0, 0, 0}, &tag), VFX_OK);
    rt_entity e[10];
    assert_int_equal(rt_world_spawn(w, 10, &a, 1, e), VFX_OK);
    for (int i = 0; i < 10; ++i)
        *(int32_t *)rt_world_get(w, e[i], a, 0) = 100 + i;
    int32_t *col_before = rt_world_get(w, e[0], a, 0);
    /* structural change in ANOTHER table leaves this table's column where it was */
    rt_component ab[2] = {a, b};
    assert_int_equal(rt_world_spawn(w, 500, ab, 2, NULL), VFX_OK);
    assert_ptr_equal(rt_world_get(w, e[0], a, 0), col_before);
    /* moving an entity to another table keeps its data; swap-remove keeps the rest right */
    assert_int_equal(rt_world_add(w, e[3], b), VFX_OK);
    assert_true(rt_world_has(w, e[3], b));
    assert_int_equal(*(int32_t *)rt_world_get(w, e[3], a, 0), 103);
    assert_int_equal(*(double *)rt_world_get(w, e[3], b, 0), 0.0); /* added zeroed */
    assert_int_equal(rt_world_add(w, e[3], tag), VFX_OK);
    assert_null(rt_world_get(w, e[3], tag, 0)); /* tags have no column */
    assert_true(rt_world_has(w, e[3], tag));
    assert_int_equal(rt_world_remove(w, e[3], b), VFX_OK);
    assert_false(rt_world_has(w, e[3], b));
    for (int i = 0; i < 10; ++i)
        assert_int_equal(*(int32_t *)rt_world_get(w, e[i], a, 0), 100 + i);
    assert_int_equal(rt_world_despawn(w, e[5]), VFX_OK);
    for (int i = 0; i < 10; ++i)
        if (i != 5)
            assert_int_equal(*(int32_t *)rt_world_get(w, e[i], a, 0), 100 + i);
    /* queries: count over all tables with `a`, and only the ones with both */
    assert_int_equal(rt_query_count(w, &a, 1), 9 + 500);
    assert_int_equal(rt_query_count(w, ab, 2), 500);
    rt_world_destroy(w);
}

static void test_permute(void **state)
{
    (void)state;
    test_log log = {0};
    rt_world *w = make_world(&log);
    rt_component a;
    assert_int_equal(rt_world_register(w, &(rt_component_desc){"a", 4, 4, 1}, &a), VFX_OK);
    rt_entity e[4];
    assert_int_equal(rt_world_spawn(w, 4, &a, 1, e), VFX_OK);
    for (int i = 0; i < 4; ++i)
        *(int32_t *)rt_world_get(w, e[i], a, 0) = i;
    uint32_t perm[4] = {3, 1, 0, 2};
    rt_query_iter it = rt_query_begin(w, &a, 1);
    assert_true(rt_query_next(&it));
    uint64_t rev = rt_world_table_revision(w, it.table);
    assert_int_equal(rt_world_table_permute(w, it.table, perm), VFX_OK);
    assert_true(rt_world_table_revision(w, it.table) > rev);
    int32_t *col = rt_query_column(&it, a, 0);
    assert_int_equal(col[0], 3);
    assert_int_equal(col[2], 0);
    for (int i = 0; i < 4; ++i) /* entity records follow their rows */
        assert_int_equal(*(int32_t *)rt_world_get(w, e[i], a, 0), i);
    uint32_t bad[4] = {0, 0, 1, 2};
    assert_int_equal(rt_world_table_permute(w, it.table, bad), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(log.last, "perm[1] = 0"));
    rt_world_destroy(w);
}

typedef struct order_log {
    char seq[64];
} order_log;

static vfx_result sys_append(rt_world *w, const rt_system_ctx *ctx)
{
    (void)w;
    order_log *l = ctx->user;
    strncat(l->seq, ctx->name, sizeof l->seq - strlen(l->seq) - 1);
    return VFX_OK;
}

static vfx_result sys_fail(rt_world *w, const rt_system_ctx *ctx)
{
    (void)w, (void)ctx;
    return VFX_ERR_NUMERIC;
}

static void test_system_order(void **state)
{
    (void)state;
    test_log log = {0};
    rt_world *w = make_world(&log);
    order_log ol = {{0}};
    rt_component a;
    assert_int_equal(rt_world_register(w, &(rt_component_desc){"a", 4, 4, 1}, &a), VFX_OK);
    /* registered out of phase order: execution is phase first, then registration order */
    const struct { const char *n; rt_phase p; } s[] = {
        {"D", RT_PHASE_POST_RENDER}, {"B", RT_PHASE_PRE_RENDER}, {"A", RT_PHASE_SIMULATE},
        {"C", RT_PHASE_PRE_RENDER}, {"E", RT_PHASE_SIMULATE}};
    for (size_t i = 0; i < 5; ++i) {
        rt_system_desc d = {.name = s[i].n, .phase = s[i].p, .reads = &a, .read_count = 1,
                             .fn = sys_append, .user = &ol};
        assert_int_equal(rt_world_add_system(w, &d), VFX_OK);
    }
    assert_int_equal(rt_world_progress(w, 0.0, 0.016f), VFX_OK);
    assert_string_equal(ol.seq, "AEBCD");
    rt_component unknown = 99;
    rt_system_desc bad = {.name = "bad", .writes = &unknown, .write_count = 1, .fn = sys_append};
    assert_int_equal(rt_world_add_system(w, &bad), VFX_ERR_INVALID_ARGUMENT);
    rt_system_desc f = {.name = "exploder", .phase = RT_PHASE_RENDER, .fn = sys_fail};
    assert_int_equal(rt_world_add_system(w, &f), VFX_OK);
    assert_int_equal(rt_world_progress(w, 0.0, 0.016f), VFX_ERR_NUMERIC);
    assert_non_null(strstr(rt_world_last_error(w), "exploder"));
    rt_world_destroy(w);
}

/* Beams are entities of one table: the column is the view's array, spawns append in order,
 * registering twice finds the same components, a volume is its own entity. */
static void test_effect_components(void **state)
{
    (void)state;
    rt_world *w = rt_world_create(NULL);
    rt_effect_components ec, again;
    assert_int_equal(rt_effects_register(w, &ec), VFX_OK);
    assert_int_equal(rt_effects_register(w, &again), VFX_OK);
    assert_true(ec.beam == again.beam && ec.volume == again.volume && ec.beam != ec.volume);
    uint32_t n = 7;
    assert_null(rt_beams_column(w, &ec, &n));
    assert_int_equal(n, 0);
    vfx_beam b[5];
    memset(b, 0, sizeof b);
    for (int i = 0; i < 5; ++i)
        b[i].length = (float)(i + 1);
    rt_entity ids[5];
    assert_int_equal(rt_beams_spawn(w, &ec, 3, b, ids), VFX_OK);
    assert_int_equal(rt_beams_spawn(w, &ec, 2, b + 3, ids + 3), VFX_OK);
    vfx_beam *col = rt_beams_column(w, &ec, &n);
    assert_int_equal(n, 5);
    for (int i = 0; i < 5; ++i) {
        assert_true(col[i].length == (float)(i + 1));
        assert_ptr_equal(rt_world_get(w, ids[i], ec.beam, 0), &col[i]);
    }
    assert_int_equal(rt_beams_spawn(w, &ec, 2, NULL, NULL), VFX_OK); /* zeroed */
    col = rt_beams_column(w, &ec, &n);
    assert_true(n == 7 && col[5].length == 0.f && col[6].length == 0.f);
    assert_true(col[5].type == VFX_TYPE_BEAM && col[6].type == VFX_TYPE_BEAM); /* typed, ready for a view */
    rt_entity v;
    assert_int_equal(rt_world_spawn(w, 1, &ec.volume, 1, &v), VFX_OK);
    assert_int_equal(rt_query_count(w, &ec.volume, 1), 1);
    assert_int_equal(rt_query_count(w, &ec.beam, 1), 7);
    rt_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ids_and_reuse),
        cmocka_unit_test(test_register_errors),
        cmocka_unit_test(test_soa_columns),
        cmocka_unit_test(test_column_stability_and_moves),
        cmocka_unit_test(test_permute),
        cmocka_unit_test(test_system_order),
        cmocka_unit_test(test_effect_components),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
