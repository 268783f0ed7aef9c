/* wrap_game.c - what a game script asks of the world, added to carom.World
 * and carom.Body: collision filtering (category, mask, group), ray casts
 * returning every hit, shape casts, exact overlaps and closest distances.
 *
 * Masks and categories are Lua integers used as 64 bit patterns (-1, that
 * is ~0, is every bit). A query's last argument may be a mask or a filter
 * function fn(body) returning false to skip a body; the function runs with
 * the world locked, and an error it raises is raised by the query once the
 * query is over (the world unchanged). */
#include <stdlib.h>
#include <string.h>
#include "carom_lua.h"

/* ---- bodies ------------------------------------------------------------------ */

carom_world *clua_check_body_id(lua_State *L, int arg, const char *fname, carom_body_id *id)
{
    clua_body *b = luaL_testudata(L, arg, CLUA_BODY_MT);
    if (!b) clua_type_error(L, arg, fname, CLUA_BODY_MT);
    lua_getiuservalue(L, arg, BODY_UV_WORLD);
    clua_world *lw = luaL_testudata(L, -1, CLUA_WORLD_MT);
    lua_pop(L, 1);
    if (!lw || !lw->world) clua_arg_error(L, arg, fname, "the body's world has been destroyed");
    if (!carom_body_is_valid(lw->world, b->id)) clua_arg_error(L, arg, fname, "body has been destroyed");
    *id = b->id;
    return lw->world;
}

/* An integer bit pattern at t[key] (a number with an integer value). */
static int field_bits(lua_State *L, int arg, const char *fname, const char *key, uint64_t *out)
{
    int t = clua_rawfield(L, arg, key);
    if (t == LUA_TNIL) { lua_pop(L, 1); return 0; }
    int isint = 0;
    lua_Integer v = lua_tointegerx(L, -1, &isint);
    if (t != LUA_TNUMBER || !isint)
        clua_arg_error(L, arg, fname, "%s must be an integer bit mask (got %s)", key,
                       t == LUA_TNUMBER ? "a fraction" : lua_typename(L, t));
    lua_pop(L, 1);
    *out = (uint64_t)v;
    return 1;
}

void clua_read_filter_keys(lua_State *L, int arg, const char *fname, carom_body_def *d)
{
    field_bits(L, arg, fname, "category", &d->category);
    field_bits(L, arg, fname, "mask", &d->mask);
    int group = d->group;
    if (clua_field_int(L, arg, fname, "group", &group)) d->group = group;
    clua_field_bool(L, arg, fname, "sensor", &d->sensor);
}

/* body:set_filter{category=, mask=, group=}: keys left out keep their value. */
static int body_set_filter(lua_State *L)
{
    static const char *const keys[] = {"category", "mask", "group", NULL};
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "set_filter", &id);
    clua_check_table(L, 2, "set_filter");
    clua_check_keys(L, 2, "set_filter", keys);
    carom_body_def d = carom_body_def_default();
    carom_body_get_filter(w, id, &d.category, &d.mask, &d.group);
    clua_read_filter_keys(L, 2, "set_filter", &d);
    w = clua_check_body_id(L, 1, "set_filter", &id);
    carom_status st = carom_body_set_filter(w, id, d.category, d.mask, d.group);
    if (st != CAROM_OK) {
        char buf[256];
        return luaL_error(L, "set_filter: %s", clua_copy_error(w, buf, sizeof buf));
    }
    return 0;
}

/* body:filter(): {category=, mask=, group=}. */
static int body_filter(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "filter", &id);
    uint64_t c = 0, m = 0;
    int g = 0;
    carom_body_get_filter(w, id, &c, &m, &g);
    lua_createtable(L, 0, 3);
    lua_pushinteger(L, (lua_Integer)c);
    lua_setfield(L, -2, "category");
    lua_pushinteger(L, (lua_Integer)m);
    lua_setfield(L, -2, "mask");
    lua_pushinteger(L, g);
    lua_setfield(L, -2, "group");
    return 1;
}

/* ---- query filters ------------------------------------------------------------ */

typedef struct lua_filter {
    lua_State *L;
    int fn_index;       /* the filter function on L's stack, or 0 */
    int world_index;
    int failed;         /* the function raised: its error is at error_index */
    int error_index;    /* a stack slot reserved for the error */
} lua_filter;

static int call_filter(lua_State *L)
{
    /* 1: the function, 2: the world, 3: the body id as light data */
    carom_body_id id = *(const carom_body_id *)lua_touserdata(L, 3);
    lua_pushvalue(L, 1);
    clua_push_body(L, 2, id);
    lua_call(L, 1, 1);
    lua_pushboolean(L, lua_toboolean(L, -1));
    return 1;
}

static int lua_filter_fn(void *context, carom_body_id body)
{
    lua_filter *f = context;
    lua_State *L = f->L;
    if (f->failed) return 0; /* after an error, skip the rest */
    int top = lua_gettop(L);
    if (!lua_checkstack(L, 8)) { f->failed = 1; lua_pushliteral(L, "query filter: Lua stack overflow"); lua_replace(L, f->error_index); return 0; }
    lua_pushcfunction(L, clua_traceback);
    lua_pushcfunction(L, call_filter);
    lua_pushvalue(L, f->fn_index);
    lua_pushvalue(L, f->world_index);
    lua_pushlightuserdata(L, &body);
    int keep = 0;
    if (lua_pcall(L, 3, 1, top + 1) != LUA_OK) {
        f->failed = 1;
        lua_replace(L, f->error_index);
    } else {
        keep = lua_toboolean(L, -1);
    }
    lua_settop(L, top);
    return keep;
}

/* Reads the optional mask-or-function at arg into filter (and *lf). */
static void read_query_filter(lua_State *L, int arg, const char *fname, carom_query_filter *filter, lua_filter *lf)
{
    *filter = carom_query_filter_default();
    memset(lf, 0, sizeof *lf);
    int t = lua_type(L, arg);
    if (t == LUA_TNONE || t == LUA_TNIL) return;
    if (t == LUA_TFUNCTION) {
        lf->L = L;
        lf->fn_index = lua_absindex(L, arg);
        lf->world_index = 1;
        lua_pushnil(L); /* the error slot */
        lf->error_index = lua_gettop(L);
        filter->fn = lua_filter_fn;
        filter->context = lf;
        return;
    }
    int isint = 0;
    lua_Integer v = lua_tointegerx(L, arg, &isint);
    if (t != LUA_TNUMBER || !isint) clua_type_error(L, arg, fname, "integer mask or filter function");
    filter->mask = (uint64_t)v;
}

/* After the query: raises what the filter function raised. */
static void finish_query_filter(lua_State *L, const lua_filter *lf)
{
    if (lf->failed) {
        lua_pushvalue(L, lf->error_index);
        lua_error(L);
    }
}

/* An orientation at arg, or nil for the identity; returns the next index. */
static int check_orientation(lua_State *L, int arg, const char *fname, carom_quat *q)
{
    if (lua_isnoneornil(L, arg)) {
        q->w = 1; q->x = q->y = q->z = 0;
        return arg + 1;
    }
    return clua_check_quat(L, arg, fname, q);
}

static int query_error(lua_State *L, clua_world *lw, int arg, const char *fname)
{
    char buf[256];
    return clua_arg_error(L, arg, fname, "%s", clua_copy_error(lw->world, buf, sizeof buf));
}

/* t.key = the 1-based part index when there is one (C's -1: none, nil). */
static void set_part(lua_State *L, const char *key, int part)
{
    if (part < 0) return;
    lua_pushinteger(L, (lua_Integer)part + 1);
    lua_setfield(L, -2, key);
}

static void push_hit(lua_State *L, const carom_ray_hit *h, int child)
{
    lua_createtable(L, 0, 5);
    clua_push_body(L, 1, h->body);
    lua_setfield(L, -2, "body");
    clua_push_vec3_table(L, h->point);
    lua_setfield(L, -2, "point");
    clua_push_vec3_table(L, h->normal);
    lua_setfield(L, -2, "normal");
    lua_pushnumber(L, h->fraction);
    lua_setfield(L, -2, "fraction");
    set_part(L, "child", child);
}

/* ---- world queries -------------------------------------------------------------- */

/* world:ray_cast_all(origin, translation [, mask or fn]): hits nearest first,
 * each {body=, point=, normal=, fraction=, child=} (child: the part hit as
 * in world:ray_cast, 1-based; nil for one-part shapes). */
static int world_ray_cast_all(lua_State *L)
{
    const char *fname = "ray_cast_all";
    clua_world *lw = clua_check_world(L, 1, fname);
    carom_vec3 origin, translation;
    int next = clua_check_vec3(L, 2, fname, &origin);
    next = clua_check_vec3(L, next, fname, &translation);
    carom_query_filter filter;
    lua_filter lf;
    read_query_filter(L, next, fname, &filter, &lf);
    lw = clua_check_world(L, 1, fname);
    int n = carom_world_ray_cast_all_children(lw->world, origin, translation, &filter, NULL, NULL, 0);
    finish_query_filter(L, &lf);
    if (n < 0) return query_error(L, lw, 2, fname);
    carom_ray_hit *hits = lua_newuserdatauv(L, sizeof *hits * (size_t)(n > 0 ? n : 1), 0);
    int *children = lua_newuserdatauv(L, sizeof *children * (size_t)(n > 0 ? n : 1), 0);
    lw = clua_check_world(L, 1, fname);
    int got = carom_world_ray_cast_all_children(lw->world, origin, translation, &filter, hits, children, n);
    finish_query_filter(L, &lf);
    if (got > n) got = n;
    lua_createtable(L, got > 0 ? got : 0, 0);
    for (int i = 0; i < got; i++) {
        push_hit(L, &hits[i], children[i]);
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

/* world:shape_cast(shape, position, orientation, translation [, mask or fn]):
 * body, fraction, point, normal, child of the first hit (child as in
 * world:ray_cast: the part touched, 1-based, nil for one-part shapes), or nil. */
static int world_shape_cast(lua_State *L)
{
    const char *fname = "shape_cast";
    clua_world *lw = clua_check_world(L, 1, fname);
    const carom_shape_def *shape = &clua_check_shape(L, 2, fname)->def;
    carom_vec3 position, translation;
    carom_quat orientation;
    int next = clua_check_vec3(L, 3, fname, &position);
    next = check_orientation(L, next, fname, &orientation);
    next = clua_check_vec3(L, next, fname, &translation);
    carom_query_filter filter;
    lua_filter lf;
    read_query_filter(L, next, fname, &filter, &lf);
    lw = clua_check_world(L, 1, fname);
    carom_ray_hit hit;
    int child = -1;
    int r = carom_world_shape_cast_child(lw->world, shape, position, orientation, translation, &filter, &hit, &child);
    finish_query_filter(L, &lf);
    if (r < 0) return query_error(L, lw, 2, fname);
    if (r == 0) {
        lua_pushnil(L);
        return 1;
    }
    clua_push_body(L, 1, hit.body);
    lua_pushnumber(L, hit.fraction);
    clua_push_vec3_table(L, hit.point);
    clua_push_vec3_table(L, hit.normal);
    if (child >= 0) lua_pushinteger(L, (lua_Integer)child + 1);
    else lua_pushnil(L);
    return 5;
}

/* world:overlap(shape, position, orientation [, mask or fn]): the bodies
 * whose shapes overlap it, in id order, and a second table: children[i] is
 * the lowest part of bodies[i] overlapped (1-based, as world:ray_cast's
 * child), nil where bodies[i] is one part (so the table may have holes). */
static int world_overlap(lua_State *L)
{
    const char *fname = "overlap";
    clua_world *lw = clua_check_world(L, 1, fname);
    const carom_shape_def *shape = &clua_check_shape(L, 2, fname)->def;
    carom_vec3 position;
    carom_quat orientation;
    int next = clua_check_vec3(L, 3, fname, &position);
    next = check_orientation(L, next, fname, &orientation);
    carom_query_filter filter;
    lua_filter lf;
    read_query_filter(L, next, fname, &filter, &lf);
    lw = clua_check_world(L, 1, fname);
    int n = carom_world_overlap_children(lw->world, shape, position, orientation, &filter, NULL, NULL, 0);
    finish_query_filter(L, &lf);
    if (n < 0) return query_error(L, lw, 2, fname);
    carom_body_id *ids = lua_newuserdatauv(L, sizeof *ids * (size_t)(n > 0 ? n : 1), 0);
    int *children = lua_newuserdatauv(L, sizeof *children * (size_t)(n > 0 ? n : 1), 0);
    lw = clua_check_world(L, 1, fname);
    int got = carom_world_overlap_children(lw->world, shape, position, orientation, &filter, ids, children, n);
    finish_query_filter(L, &lf);
    if (got > n) got = n;
    lua_createtable(L, got > 0 ? got : 0, 0);
    lua_createtable(L, 0, 0);
    for (int i = 0; i < got; i++) {
        clua_push_body(L, 1, ids[i]);
        lua_rawseti(L, -3, i + 1);
        if (children[i] < 0) continue;
        lua_pushinteger(L, (lua_Integer)children[i] + 1);
        lua_rawseti(L, -2, i + 1);
    }
    return 2;
}

/* world:distance(a, b): distance (negative when they overlap), point on a,
 * point on b. */
static int world_distance(lua_State *L)
{
    const char *fname = "distance";
    clua_world *lw = clua_check_world(L, 1, fname);
    carom_body_id a, b;
    carom_world *wa = clua_check_body_id(L, 2, fname, &a);
    carom_world *wb = clua_check_body_id(L, 3, fname, &b);
    if (wa != lw->world) clua_arg_error(L, 2, fname, "body belongs to another world");
    if (wb != lw->world) clua_arg_error(L, 3, fname, "body belongs to another world");
    carom_distance_result r;
    carom_status st = carom_world_body_distance(lw->world, a, b, &r);
    if (st != CAROM_OK) return query_error(L, lw, 3, fname);
    lua_pushnumber(L, r.distance);
    clua_push_vec3_table(L, r.point_a);
    clua_push_vec3_table(L, r.point_b);
    return 3;
}

/* ---- body calls ------------------------------------------------------------------ */

static int game_status(lua_State *L, carom_world *w, carom_status st, int arg, const char *fname)
{
    if (st == CAROM_OK) return 0;
    char buf[256];
    const char *msg = clua_copy_error(w, buf, sizeof buf);
    if (st == CAROM_ERROR_INVALID_ARGUMENT && arg > 0) return clua_arg_error(L, arg, fname, "%s", msg);
    return luaL_error(L, "%s: %s", fname, msg);
}

/* body:apply_angular_impulse(L): spin changes by I^-1 L (deferred inside a callback). */
static int body_apply_angular_impulse(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "apply_angular_impulse", &id);
    carom_vec3 v;
    clua_check_vec3(L, 2, "apply_angular_impulse", &v);
    w = clua_check_body_id(L, 1, "apply_angular_impulse", &id);
    return game_status(L, w, carom_body_apply_angular_impulse(w, id, v), 2, "apply_angular_impulse");
}

/* body:set_damping(linear, angular) */
static int body_set_damping(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "set_damping", &id);
    double lin = clua_check_number(L, 2, "set_damping"), ang = clua_check_number(L, 3, "set_damping");
    /* which argument C refused, by status: the linear one alone first (with
     * the angular kept), then both; a refused second call puts the first back */
    double old_lin = 0.0, old_ang = 0.0;
    carom_status st = carom_body_get_damping(w, id, &old_lin, &old_ang);
    if (st == CAROM_OK) st = carom_body_set_damping(w, id, lin, old_ang);
    if (st != CAROM_OK) return game_status(L, w, st, 2, "set_damping");
    st = carom_body_set_damping(w, id, lin, ang);
    if (st != CAROM_OK) {
        char buf[256];
        const char *msg = clua_copy_error(w, buf, sizeof buf);
        carom_body_set_damping(w, id, old_lin, old_ang);
        if (st == CAROM_ERROR_INVALID_ARGUMENT) return clua_arg_error(L, 3, "set_damping", "%s", msg);
        return luaL_error(L, "%s: %s", "set_damping", msg);
    }
    return 0;
}

/* body:damping(): linear, angular */
static int body_damping(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "damping", &id);
    double lin = 0, ang = 0;
    carom_body_get_damping(w, id, &lin, &ang);
    lua_pushnumber(L, lin);
    lua_pushnumber(L, ang);
    return 2;
}

typedef carom_status convert_fn(const carom_world *, carom_body_id, carom_vec3, carom_vec3 *);
static int convert(lua_State *L, const char *fname, convert_fn *fn)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, fname, &id);
    carom_vec3 in, out = {0, 0, 0};
    clua_check_vec3(L, 2, fname, &in);
    w = clua_check_body_id(L, 1, fname, &id);
    game_status(L, w, fn(w, id, in, &out), 2, fname);
    return clua_return_vec3(L, out);
}
static int body_world_point(lua_State *L) { return convert(L, "world_point", carom_body_get_world_point); }
static int body_local_point(lua_State *L) { return convert(L, "local_point", carom_body_get_local_point); }
static int body_world_vector(lua_State *L) { return convert(L, "world_vector", carom_body_get_world_vector); }
static int body_local_vector(lua_State *L) { return convert(L, "local_vector", carom_body_get_local_vector); }

/* body:shape(): a new shape value equal to the body's (usable in add_body and queries). */
static int body_shape(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "shape", &id);
    carom_shape_def d;
    carom_body_get_shape(w, id, &d);
    clua_shape *s = lua_newuserdatauv(L, sizeof *s, 0);
    memset(s, 0, sizeof *s);
    luaL_setmetatable(L, CLUA_SHAPE_MT); /* its __gc frees the points */
    if (d.type == CAROM_SHAPE_HULL) {
        s->points = malloc(sizeof(double) * 3 * (size_t)d.point_count);
        if (!s->points) return luaL_error(L, "shape: out of memory");
        memcpy(s->points, d.points, sizeof(double) * 3 * (size_t)d.point_count);
        d.points = s->points;
    }
    s->def = d;
    return 1;
}

static int body_previous_position(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "previous_position", &id);
    carom_vec3 p = {0, 0, 0};
    carom_body_get_previous_position(w, id, &p);
    return clua_return_vec3(L, p);
}

static int body_previous_orientation(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "previous_orientation", &id);
    carom_quat q = {1, 0, 0, 0};
    carom_body_get_previous_orientation(w, id, &q);
    lua_pushnumber(L, q.w);
    lua_pushnumber(L, q.x);
    lua_pushnumber(L, q.y);
    lua_pushnumber(L, q.z);
    return 4;
}

/* ---- sensors, pre-solve, contacts ---------------------------------------------------- */

static int body_is_sensor(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "is_sensor", &id);
    lua_pushboolean(L, carom_body_is_sensor(w, id));
    return 1;
}

/* body:contacts(): the touching contacts, each {other=, normal=, point=,
 * separation=, points=, impulse=, child=, other_child=} (normal from this
 * body to other; child and other_child: the part of this body and of other
 * the contact is on, as carom_body_get_contact_children names it, 1-based,
 * nil for one-part shapes). */
static int body_contacts(lua_State *L)
{
    carom_body_id id;
    carom_world *w = clua_check_body_id(L, 1, "contacts", &id);
    int n = carom_body_get_contacts(w, id, NULL, 0);
    if (n < 0) n = 0;
    carom_contact_info *info = lua_newuserdatauv(L, sizeof *info * (size_t)(n > 0 ? n : 1), 0);
    int *mine = lua_newuserdatauv(L, sizeof *mine * 2 * (size_t)(n > 0 ? n : 1), 0), *theirs = mine + (n > 0 ? n : 1);
    w = clua_check_body_id(L, 1, "contacts", &id);
    int got = carom_body_get_contacts(w, id, info, n);
    if (got > n) got = n;
    /* the same contacts in the same order: nothing ran in between */
    if (carom_body_get_contact_children(w, id, mine, theirs, got) < 0)
        for (int i = 0; i < got; i++) mine[i] = theirs[i] = -1;
    lua_getiuservalue(L, 1, BODY_UV_WORLD);
    int world_index = lua_gettop(L);
    lua_createtable(L, got > 0 ? got : 0, 0);
    for (int i = 0; i < got; i++) {
        lua_createtable(L, 0, 8);
        clua_push_body(L, world_index, info[i].other);
        lua_setfield(L, -2, "other");
        clua_push_vec3_table(L, info[i].normal);
        lua_setfield(L, -2, "normal");
        clua_push_vec3_table(L, info[i].point);
        lua_setfield(L, -2, "point");
        lua_pushnumber(L, info[i].separation);
        lua_setfield(L, -2, "separation");
        lua_pushinteger(L, info[i].point_count);
        lua_setfield(L, -2, "points");
        lua_pushnumber(L, info[i].normal_impulse);
        lua_setfield(L, -2, "impulse");
        set_part(L, "child", mine[i]);
        set_part(L, "other_child", theirs[i]);
        lua_rawseti(L, -2, i + 1);
    }
    return 1;
}

static const char pre_solve_key = 'p';   /* registry: weak-keyed {world userdata = fn} */
static const char pair_filter_key = 'f'; /* the same for the pair filter */

/* Inside a dispatcher: pushes the world's function under key and bodies a, b
 * (light ids at 2 and 3). */
static void push_hook(lua_State *L, const char *key)
{
    const carom_body_id *a = lua_touserdata(L, 2), *b = lua_touserdata(L, 3);
    lua_rawgetp(L, LUA_REGISTRYINDEX, key);
    lua_pushvalue(L, 1);
    lua_rawget(L, -2);
    clua_push_body(L, 1, *a);
    clua_push_body(L, 1, *b);
}

/* The hook's answer: only false refuses. */
static int hook_answer(lua_State *L)
{
    lua_pushboolean(L, !(lua_type(L, -1) == LUA_TBOOLEAN && !lua_toboolean(L, -1)));
    return 1;
}

/* Runs protected inside the step: 1 = world, 2 = a, 3 = b (light ids), 4 = manifold. */
static int dispatch_pre_solve(lua_State *L)
{
    const carom_manifold *m = lua_touserdata(L, 4);
    push_hook(L, &pre_solve_key);
    lua_createtable(L, 0, 3);
    clua_push_vec3_table(L, m->normal);
    lua_setfield(L, -2, "normal");
    lua_createtable(L, m->point_count, 0);
    lua_createtable(L, m->point_count, 0);
    for (int i = 0; i < m->point_count; i++) {
        clua_push_vec3_table(L, m->points[i]);
        lua_rawseti(L, -3, i + 1);
        lua_pushnumber(L, m->separations[i]);
        lua_rawseti(L, -2, i + 1);
    }
    lua_setfield(L, -3, "separations");
    lua_setfield(L, -2, "points");
    lua_call(L, 3, 1);
    return hook_answer(L);
}

/* Runs protected inside the step: 1 = world, 2 = a, 3 = b (light ids). */
static int dispatch_pair_filter(lua_State *L)
{
    push_hook(L, &pair_filter_key);
    lua_call(L, 2, 1);
    return hook_answer(L);
}

/* Calls dispatch(world, a, b[, m]) protected on the stepping state; an error
 * is kept for the step to raise afterwards, like a contact callback's, and
 * the pair kept. Returns 1 to keep the pair. */
static int run_hook(clua_world *lw, lua_CFunction dispatch, carom_body_id a, carom_body_id b, const carom_manifold *m)
{
    lua_State *L = lw->stepping;
    if (!L || lw->callback_failed) return 1;
    int top = lua_gettop(L);
    if (!lua_checkstack(L, 12)) return 1;
    lua_pushcfunction(L, clua_traceback);
    lua_pushcfunction(L, dispatch);
    lua_pushvalue(L, 1);
    lua_pushlightuserdata(L, &a);
    lua_pushlightuserdata(L, &b);
    if (m) lua_pushlightuserdata(L, (void *)m);
    int keep = 1;
    if (lua_pcall(L, m ? 4 : 3, 1, top + 1) != LUA_OK) {
        lw->callback_failed = 1;
        lua_setiuservalue(L, 1, WORLD_UV_ERROR);
    } else {
        keep = lua_toboolean(L, -1);
    }
    lua_settop(L, top);
    return keep;
}

static int lua_pre_solve(void *context, carom_body_id a, carom_body_id b, const carom_manifold *m)
{
    return run_hook(context, dispatch_pre_solve, a, b, m);
}

static int lua_pair_filter(void *context, carom_body_id a, carom_body_id b)
{
    return run_hook(context, dispatch_pair_filter, a, b, NULL);
}

/* world:set_...(fn or nil): checks it and keeps fn under key for the world;
 * returns the world for the C setter. */
static clua_world *set_hook(lua_State *L, const char *key, const char *name)
{
    clua_world *lw = clua_check_world(L, 1, name);
    if (!lua_isnil(L, 2) && lua_type(L, 2) != LUA_TFUNCTION) clua_type_error(L, 2, name, "function or nil");
    if (lw->stepping) luaL_error(L, "%s: cannot change it inside a contact callback", name);
    lua_settop(L, 2);
    lua_rawgetp(L, LUA_REGISTRYINDEX, key);
    lua_pushvalue(L, 1);
    lua_pushvalue(L, 2);
    lua_rawset(L, -3);
    return clua_check_world(L, 1, name);
}

/* world:set_pair_filter(fn or nil): fn(a, b) for each new pair the bits
 * allow (contacts and continuous collision); returning false keeps them
 * from touching. */
static int world_set_pair_filter(lua_State *L)
{
    clua_world *lw = set_hook(L, &pair_filter_key, "set_pair_filter");
    carom_world_set_pair_filter(lw->world, lua_isfunction(L, 2) ? lua_pair_filter : NULL, lw);
    return 0;
}

/* world:set_pre_solve(fn or nil): fn(a, b, manifold) before each touching
 * pair is solved; returning false leaves it out of this step. */
static int world_set_pre_solve(lua_State *L)
{
    clua_world *lw = set_hook(L, &pre_solve_key, "set_pre_solve");
    carom_world_set_pre_solve(lw->world, lua_isfunction(L, 2) ? lua_pre_solve : NULL, lw);
    return 0;
}

void clua_open_game(lua_State *L)
{
    static const luaL_Reg world_methods[] = {{"ray_cast_all", world_ray_cast_all}, {"shape_cast", world_shape_cast},
                                             {"overlap", world_overlap}, {"distance", world_distance},
                                             {"set_pre_solve", world_set_pre_solve},
                                             {"set_pair_filter", world_set_pair_filter}, {NULL, NULL}};
    static const luaL_Reg body_methods[] = {
        {"set_filter", body_set_filter}, {"filter", body_filter}, {"apply_angular_impulse", body_apply_angular_impulse},
        {"set_damping", body_set_damping}, {"damping", body_damping}, {"world_point", body_world_point},
        {"local_point", body_local_point}, {"world_vector", body_world_vector}, {"local_vector", body_local_vector},
        {"shape", body_shape}, {"previous_position", body_previous_position},
        {"previous_orientation", body_previous_orientation}, {"is_sensor", body_is_sensor},
        {"contacts", body_contacts}, {NULL, NULL}};
    lua_newtable(L); /* pre-solve functions by world, weak keys: the world's life decides */
    lua_createtable(L, 0, 1);
    lua_pushliteral(L, "k");
    lua_setfield(L, -2, "__mode");
    lua_setmetatable(L, -2);
    lua_rawsetp(L, LUA_REGISTRYINDEX, &pre_solve_key);
    lua_newtable(L); /* pair filters likewise */
    lua_createtable(L, 0, 1);
    lua_pushliteral(L, "k");
    lua_setfield(L, -2, "__mode");
    lua_setmetatable(L, -2);
    lua_rawsetp(L, LUA_REGISTRYINDEX, &pair_filter_key);
    luaL_getmetatable(L, CLUA_WORLD_MT);
    lua_getfield(L, -1, "__index");
    luaL_setfuncs(L, world_methods, 0);
    lua_pop(L, 2);
    luaL_getmetatable(L, CLUA_BODY_MT);
    lua_getfield(L, -1, "__index"); /* a closure over the methods table */
    lua_getupvalue(L, -1, 1);
    luaL_setfuncs(L, body_methods, 0);
    lua_pop(L, 3);
}
