/* wrap_shape.c - shape descriptors: carom.sphere{radius}, carom.box{half_extents},
 * carom.capsule{radius, half_height}, carom.cylinder{radius, half_height},
 * carom.hull{points}, carom.plane{normal, offset}. Each field may be given by
 * name or by position (carom.capsule{0.1, 0.3}). A descriptor is validated
 * when made and never changes; add_body copies it into the world, so one
 * descriptor can serve many bodies. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "carom_lua.h"

const char *const clua_shape_names[] = {"sphere", "box", "capsule", "cylinder", "hull", "plane", "mesh", "heightfield", "compound", NULL};

/* Largest hull input accepted here; the world refuses hulls whose result is
 * larger than its narrowphase holds, with its own message. */

clua_shape *clua_check_shape(lua_State *L, int arg, const char *fname)
{
    clua_shape *s = luaL_testudata(L, arg, CLUA_SHAPE_MT);
    if (!s) clua_type_error(L, arg, fname, "shape (carom.sphere, box, capsule, cylinder, hull, plane, mesh, heightfield or compound)");
    return s;
}

static clua_shape *new_shape(lua_State *L)
{
    clua_shape *s = lua_newuserdatauv(L, sizeof *s, 0);
    memset(s, 0, sizeof *s);
    luaL_setmetatable(L, CLUA_SHAPE_MT);
    return s;
}

/* Checks the options table of a shape constructor: named keys from `names`,
 * or positions 1..#names. */
static void check_shape_args(lua_State *L, const char *fname, const char *const *names)
{
    clua_check_table(L, 1, fname);
    int count = 0;
    while (names[count]) count++;
    clua_check_option_keys(L, 1, fname, names, count);
}

/* Moves t[position] to t[name] in a private copy of the options table at 1,
 * so the field readers below see one spelling; duplicates are an error. */
static void normalise_positions(lua_State *L, const char *fname, const char *const *names)
{
    lua_newtable(L);
    for (int i = 0; names[i]; i++) {
        int by_name = clua_rawfield(L, 1, names[i]) != LUA_TNIL;
        int by_pos = lua_rawgeti(L, 1, i + 1) != LUA_TNIL;
        if (by_name && by_pos) clua_arg_error(L, 1, fname, "%s given twice (by name and by position)", names[i]);
        if (by_name) lua_pop(L, 1);
        else lua_remove(L, -2);
        lua_setfield(L, -2, names[i]);
    }
    lua_replace(L, 1);
}

static double required_field(lua_State *L, const char *fname, const char *key)
{
    double v = 0;
    if (!clua_field_number(L, 1, fname, key, &v)) clua_arg_error(L, 1, fname, "%s is required", key);
    return v;
}

/* The library's own check of the def (as carom_body_create applies it to a
 * static body; the body's type is checked again there): its reason as the
 * argument error. */
static void check_def(lua_State *L, const char *fname, const carom_shape_def *def)
{
    char msg[256];
    if (carom_shape_def_check(def, CAROM_BODY_STATIC, msg, sizeof msg) == CAROM_OK) return;
    clua_arg_error(L, 1, fname, "%s", msg);
}

static int l_sphere(lua_State *L)
{
    static const char *const keys[] = {"radius", NULL};
    check_shape_args(L, "sphere", keys);
    normalise_positions(L, "sphere", keys);
    carom_shape_def def = carom_shape_sphere(required_field(L, "sphere", "radius"));
    check_def(L, "sphere", &def);
    new_shape(L)->def = def;
    return 1;
}

static int l_box(lua_State *L)
{
    static const char *const keys[] = {"half_extents", NULL};
    check_shape_args(L, "box", keys);
    normalise_positions(L, "box", keys);
    carom_vec3 h;
    if (!clua_field_vec3(L, 1, "box", "half_extents", &h)) clua_arg_error(L, 1, "box", "half_extents is required");
    carom_shape_def def = carom_shape_box(h.x, h.y, h.z);
    check_def(L, "box", &def);
    new_shape(L)->def = def;
    return 1;
}

static int round_shape(lua_State *L, const char *fname, int capsule)
{
    static const char *const keys[] = {"radius", "half_height", NULL};
    check_shape_args(L, fname, keys);
    normalise_positions(L, fname, keys);
    double r = required_field(L, fname, "radius");
    double h = required_field(L, fname, "half_height");
    carom_shape_def def = capsule ? carom_shape_capsule(r, h) : carom_shape_cylinder(r, h);
    check_def(L, fname, &def);
    new_shape(L)->def = def;
    return 1;
}

static int l_capsule(lua_State *L) { return round_shape(L, "capsule", 1); }
static int l_cylinder(lua_State *L) { return round_shape(L, "cylinder", 0); }

/* carom.hull{points = {{x,y,z}, ...}}, or the points directly: carom.hull{{x,y,z}, ...} */
static int l_hull(lua_State *L)
{
    clua_check_table(L, 1, "hull");
    int points_index;
    int direct = lua_rawgeti(L, 1, 1) == LUA_TTABLE && lua_rawgeti(L, -1, 1) == LUA_TNUMBER;
    lua_settop(L, 1);
    if (direct) {
        points_index = 1;
        lua_pushnil(L);
        while (lua_next(L, 1)) {
            lua_pop(L, 1);
            if (!lua_isinteger(L, -1)) clua_arg_error(L, 1, "hull", "a list of points takes no named options");
        }
    } else {
        static const char *const keys[] = {"points", NULL};
        check_shape_args(L, "hull", keys);
        normalise_positions(L, "hull", keys);
        if (clua_rawfield(L, 1, "points") != LUA_TTABLE)
            clua_arg_error(L, 1, "hull", "points must be a table of vectors {{x, y, z}, ...}");
        points_index = lua_gettop(L);
    }
    lua_Integer n = (lua_Integer)lua_rawlen(L, points_index);
    if (n > INT_MAX / 3) clua_arg_error(L, 1, "hull", "%lld points are too many to read", (long long)n);
    clua_shape *s = new_shape(L); /* owns the array from here, so an error below cannot leak it */
    s->points = malloc(sizeof(double) * 3 * (size_t)(n > 0 ? n : 1));
    if (!s->points) return luaL_error(L, "hull: out of memory");
    for (lua_Integer i = 0; i < n; i++) {
        lua_rawgeti(L, points_index, i + 1);
        if (lua_type(L, -1) != LUA_TTABLE) clua_arg_error(L, 1, "hull", "point %d is not a vector {x, y, z}", (int)i + 1);
        for (int c = 0; c < 3; c++) {
            if (lua_rawgeti(L, -1, c + 1) != LUA_TNUMBER) clua_arg_error(L, 1, "hull", "point %d is not a vector of 3 numbers", (int)i + 1);
            double v = lua_tonumber(L, -1);
            if (!isfinite(v)) clua_arg_error(L, 1, "hull", "point %d is not finite", (int)i + 1);
            s->points[3 * i + c] = v;
            lua_pop(L, 1);
        }
        lua_pop(L, 1);
    }
    s->def = carom_shape_hull(s->points, (int)n);
    check_def(L, "hull", &s->def);
    return 1;
}

static int l_plane(lua_State *L)
{
    static const char *const keys[] = {"normal", "offset", NULL};
    if (lua_isnoneornil(L, 1)) {
        lua_settop(L, 0);
        lua_newtable(L);
    }
    check_shape_args(L, "plane", keys);
    normalise_positions(L, "plane", keys);
    carom_vec3 n = {0, 0, 1};
    double offset = 0;
    clua_field_vec3(L, 1, "plane", "normal", &n);
    clua_field_number(L, 1, "plane", "offset", &offset);
    carom_shape_def def = carom_shape_plane(n.x, n.y, n.z, offset);
    check_def(L, "plane", &def);
    new_shape(L)->def = def;
    return 1;
}

/* ---- level geometry ---------------------------------------------------------- */

/* Reads the list at index t as n groups of `width` numbers: either a list of
 * groups ({{x, y, z}, ...}) or a flat list of numbers. Returns n; out is
 * malloc'ed (what = the field's name, for errors). */
static int read_groups(lua_State *L, const char *fname, const char *what, int t, int width, double **out)
{
    lua_Integer len = (lua_Integer)lua_rawlen(L, t);
    int nested = len > 0 && lua_rawgeti(L, t, 1) == LUA_TTABLE;
    lua_settop(L, lua_gettop(L) - (len > 0 ? 1 : 0));
    if (!nested && len % width != 0)
        clua_arg_error(L, 1, fname, "%s: a flat list needs a multiple of %d numbers, got %d", what, width, (int)len);
    lua_Integer n = nested ? len : len / width;
    if (n > 100000000) clua_arg_error(L, 1, fname, "%s: too many entries (%lld)", what, (long long)n);
    double *v = malloc(sizeof *v * (size_t)(n > 0 ? n : 1) * (size_t)width);
    if (!v) return luaL_error(L, "%s: out of memory", fname);
    for (lua_Integer i = 0; i < n; i++) {
        if (nested) {
            if (lua_rawgeti(L, t, i + 1) != LUA_TTABLE || lua_rawlen(L, -1) != (size_t)width) {
                free(v);
                clua_arg_error(L, 1, fname, "%s[%d] is not a list of %d numbers", what, (int)i + 1, width);
            }
            for (int c = 0; c < width; c++) {
                if (lua_rawgeti(L, -1, c + 1) != LUA_TNUMBER) {
                    free(v);
                    clua_arg_error(L, 1, fname, "%s[%d] is not a list of %d numbers", what, (int)i + 1, width);
                }
                v[width * i + c] = lua_tonumber(L, -1);
                lua_pop(L, 1);
            }
            lua_pop(L, 1);
        } else {
            for (int c = 0; c < width; c++) {
                if (lua_rawgeti(L, t, width * i + c + 1) != LUA_TNUMBER) {
                    free(v);
                    clua_arg_error(L, 1, fname, "%s[%d] is not a number", what, (int)(width * i + c) + 1);
                }
                v[width * i + c] = lua_tonumber(L, -1);
                lua_pop(L, 1);
            }
        }
    }
    *out = v;
    return (int)n;
}

/* The 1-based integers in v (n of them) as 0-based ints below limit. An
 * index names an element of one of the script's lists (1..#list), so
 * whether that element exists is the binding's question: the library sees
 * only 0-based indices (and checks them again). */
static int *to_indices(lua_State *L, const char *fname, const char *what, double *v, int n, int limit, int width)
{
    int *ix = malloc(sizeof *ix * (size_t)(n > 0 ? n : 1));
    if (!ix) { free(v); luaL_error(L, "%s: out of memory", fname); return NULL; }
    for (int i = 0; i < n; i++) {
        double x = v[i];
        if (!(x == floor(x) && x >= 1 && x <= limit)) {
            char num[32];
            snprintf(num, sizeof num, "%.17g", x);
            free(ix);
            free(v);
            if (width > 1) clua_arg_error(L, 1, fname, "%s[%d]: index %s is not an integer in 1..%d", what, i / width + 1, num, limit);
            else clua_arg_error(L, 1, fname, "%s[%d]: %s is not an integer in 1..%d", what, i + 1, num, limit);
        }
        ix[i] = (int)x - 1;
    }
    free(v);
    return ix;
}

/* carom.mesh{vertices = {{x, y, z}, ...}, triangles = {{i, j, k}, ...}, two_sided = false}:
 * 1-based indices, counter-clockwise seen from the front; flat number lists too. */
static int l_mesh(lua_State *L)
{
    static const char *const keys[] = {"vertices", "triangles", "two_sided", NULL};
    check_shape_args(L, "mesh", keys);
    normalise_positions(L, "mesh", keys);
    if (clua_rawfield(L, 1, "vertices") != LUA_TTABLE) clua_arg_error(L, 1, "mesh", "vertices must be a list of {x, y, z}");
    if (clua_rawfield(L, 1, "triangles") != LUA_TTABLE) clua_arg_error(L, 1, "mesh", "triangles must be a list of {i, j, k}");
    int two_sided = 0;
    clua_field_bool(L, 1, "mesh", "two_sided", &two_sided);
    clua_shape *s = new_shape(L); /* owns the arrays from here (collected on error) */
    int nv = read_groups(L, "mesh", "vertices", 2, 3, &s->points);
    double *tv;
    int nt = read_groups(L, "mesh", "triangles", 3, 3, &tv);
    s->indices = to_indices(L, "mesh", "triangles", tv, 3 * nt, nv, 3);
    s->def = carom_shape_sphere(1);
    s->def.type = CAROM_SHAPE_MESH;
    s->mesh = carom_mesh_def_default();
    s->mesh.vertices = s->points; s->mesh.vertex_count = nv;
    s->mesh.triangles = s->indices; s->mesh.triangle_count = nt;
    s->mesh.two_sided = two_sided;
    /* the library's rules (counts, coordinates, repeated indices); a mesh of
     * only zero-area triangles is refused when the body is made */
    char msg[256];
    if (carom_mesh_def_check(&s->mesh, msg, sizeof msg) != CAROM_OK) clua_arg_error(L, 1, "mesh", "%s", msg);
    return 1;
}

/* carom.heightfield{heights = {...}, rows = R, columns = C, cell = {dx, dy}, holes = {...}}:
 * heights row by row, row 1 at the lowest y; holes are 1-based cell indices. */
static int l_heightfield(lua_State *L)
{
    static const char *const keys[] = {"heights", "rows", "columns", "cell", "holes", NULL};
    check_shape_args(L, "heightfield", keys);
    normalise_positions(L, "heightfield", keys);
    int rows = 0, columns = 0;
    if (!clua_field_int(L, 1, "heightfield", "rows", &rows)) clua_arg_error(L, 1, "heightfield", "rows is required");
    if (!clua_field_int(L, 1, "heightfield", "columns", &columns))
        clua_arg_error(L, 1, "heightfield", "columns is required");
    double dx = 1, dy = 1;
    int ct = clua_rawfield(L, 1, "cell");
    if (ct == LUA_TNUMBER) dx = dy = lua_tonumber(L, -1);
    else if (ct == LUA_TTABLE) {
        if (lua_rawgeti(L, -1, 1) != LUA_TNUMBER || lua_rawgeti(L, -2, 2) != LUA_TNUMBER)
            clua_arg_error(L, 1, "heightfield", "cell must be {dx, dy} or a number");
        dx = lua_tonumber(L, -2); dy = lua_tonumber(L, -1);
        lua_pop(L, 2);
    } else if (ct != LUA_TNIL) clua_arg_error(L, 1, "heightfield", "cell must be {dx, dy} or a number");
    lua_pop(L, 1);
    if (clua_rawfield(L, 1, "heights") != LUA_TTABLE) clua_arg_error(L, 1, "heightfield", "heights must be a list of numbers");
    int ht = lua_gettop(L);
    int has_holes = clua_rawfield(L, 1, "holes") != LUA_TNIL;
    if (has_holes && lua_type(L, -1) != LUA_TTABLE) clua_arg_error(L, 1, "heightfield", "holes must be a list of cell indices");
    int hl = lua_gettop(L);
    clua_shape *s = new_shape(L);
    int n = read_groups(L, "heightfield", "heights", ht, 1, &s->points);
    /* the library reads rows x columns heights: the list must hold that many
     * (how many rows and columns may be is the library's question) */
    long long want = (long long)rows * columns;
    if (n != want) clua_arg_error(L, 1, "heightfield", "heights: need rows x columns = %lld numbers, got %d", want, n);
    int nh = 0;
    if (has_holes) {
        double *hv;
        nh = read_groups(L, "heightfield", "holes", hl, 1, &hv);
        long long cells = (long long)(rows > 1 ? rows - 1 : 0) * (columns > 1 ? columns - 1 : 0);
        s->indices = to_indices(L, "heightfield", "holes", hv, nh, (int)cells, 1);
    }
    s->def = carom_shape_sphere(1);
    s->def.type = CAROM_SHAPE_HEIGHTFIELD;
    s->heightfield = carom_heightfield_def_default();
    s->heightfield.heights = s->points;
    s->heightfield.rows = (int)rows; s->heightfield.columns = (int)columns;
    s->heightfield.cell_x = dx; s->heightfield.cell_y = dy;
    s->heightfield.holes = s->indices; s->heightfield.hole_count = nh;
    char msg[256];
    if (carom_heightfield_def_check(&s->heightfield, msg, sizeof msg) != CAROM_OK)
        clua_arg_error(L, 1, "heightfield", "%s", msg);
    return 1;
}

/* carom.compound{ {shape = carom.box{...}, position = {...}, orientation = {...},
 * friction = 0.6, restitution = 0, density = 1000}, ... }: convex children */
static int l_compound(lua_State *L)
{
    static const char *const child_keys[] = {"shape", "position", "orientation", "friction", "restitution", "density", "material", NULL};
    clua_check_table(L, 1, "compound");
    lua_settop(L, 1);
    lua_Integer n = (lua_Integer)lua_rawlen(L, 1);
    lua_pushnil(L);
    while (lua_next(L, 1)) {
        lua_pop(L, 1);
        if (!lua_isinteger(L, -1) || lua_tointeger(L, -1) < 1 || lua_tointeger(L, -1) > n)
            clua_arg_error(L, 1, "compound", "takes a list of children {shape = ..., position = ...}, no named options");
    }
    if (n > INT_MAX / 2) clua_arg_error(L, 1, "compound", "%lld children are too many to read", (long long)n);
    /* the hull children's points, all in one buffer */
    size_t total = 0;
    for (lua_Integer i = 1; i <= n; i++) {
        if (lua_rawgeti(L, 1, i) != LUA_TTABLE) clua_arg_error(L, 1, "compound", "child %d is not a table", (int)i);
        clua_rawfield(L, lua_gettop(L), "shape");
        clua_shape *cs = luaL_testudata(L, -1, CLUA_SHAPE_MT);
        if (!cs) clua_arg_error(L, 1, "compound", "child %d: shape must be made by carom.sphere, box, capsule, cylinder or hull", (int)i);
        carom_shape_type t = cs->def.type;
        if (t != CAROM_SHAPE_SPHERE && t != CAROM_SHAPE_BOX && t != CAROM_SHAPE_CAPSULE && t != CAROM_SHAPE_CYLINDER &&
            t != CAROM_SHAPE_HULL)
            clua_arg_error(L, 1, "compound", "child %d: shape must be convex (sphere, box, capsule, cylinder or hull), got a %s",
                           (int)i, clua_shape_names[t]);
        if (t == CAROM_SHAPE_HULL) total += 3 * (size_t)cs->def.point_count;
        lua_pop(L, 2);
    }
    clua_shape *s = new_shape(L);
    int self = lua_gettop(L);
    s->children = calloc((size_t)(n > 0 ? n : 1), sizeof *s->children);
    s->materials = calloc((size_t)(n > 0 ? n : 1), sizeof *s->materials);
    s->points = malloc(sizeof *s->points * (total > 0 ? total : 1));
    if (!s->children || !s->points || !s->materials) return luaL_error(L, "compound: out of memory");
    size_t used = 0;
    for (lua_Integer i = 1; i <= n; i++) {
        char who[48];
        snprintf(who, sizeof who, "compound child %d", (int)i);
        lua_rawgeti(L, 1, i);
        int ct = lua_gettop(L);
        clua_check_option_keys(L, ct, who, child_keys, 0);
        clua_rawfield(L, ct, "shape");
        const clua_shape *cs = lua_touserdata(L, -1);
        carom_compound_child c = carom_compound_child_default(cs->def);
        if (cs->def.type == CAROM_SHAPE_HULL) {
            memcpy(s->points + used, cs->points, sizeof *s->points * 3 * (size_t)cs->def.point_count);
            c.shape.points = s->points + used;
            used += 3 * (size_t)cs->def.point_count;
        }
        lua_pop(L, 1);
        clua_field_vec3(L, ct, who, "position", &c.position);
        clua_field_quat(L, ct, who, "orientation", &c.orientation);
        clua_field_number(L, ct, who, "friction", &c.friction);
        clua_field_number(L, ct, who, "restitution", &c.restitution);
        clua_field_number(L, ct, who, "density", &c.density);
        if (clua_rawfield(L, ct, "material") != LUA_TNIL) {
            const carom_material *m = luaL_testudata(L, -1, CLUA_MATERIAL_MT);
            if (!m) clua_arg_error(L, ct, who, "material must be made by carom.material{...}, got %s", luaL_typename(L, -1));
            s->materials[i - 1] = *m; /* the shape keeps its own copy */
            c.material = &s->materials[i - 1];
        }
        lua_pop(L, 1);
        s->children[i - 1] = c;
        s->child_count = (int)i;
        lua_settop(L, self);
    }
    s->def = carom_shape_sphere(1);
    s->def.type = CAROM_SHAPE_COMPOUND;
    char msg[256];
    if (carom_compound_check(s->children, s->child_count, msg, sizeof msg) != CAROM_OK)
        clua_arg_error(L, 1, "compound", "%s", msg);
    return 1;
}

/* ---- metamethods ----------------------------------------------------------- */

static int shape_gc(lua_State *L)
{
    clua_shape *s = luaL_checkudata(L, 1, CLUA_SHAPE_MT);
    free(s->points);
    free(s->indices);
    free(s->children);
    free(s->materials);
    s->materials = NULL;
    s->points = NULL;
    s->indices = NULL;
    s->children = NULL;
    s->def.points = NULL;
    s->def.point_count = 0;
    return 0;
}

static int shape_tostring(lua_State *L)
{
    const carom_shape_def *d = &((clua_shape *)luaL_checkudata(L, 1, CLUA_SHAPE_MT))->def;
    char buf[200];
    switch (d->type) {
    case CAROM_SHAPE_SPHERE: snprintf(buf, sizeof buf, "carom.sphere{radius = %g}", d->radius); break;
    case CAROM_SHAPE_BOX:
        snprintf(buf, sizeof buf, "carom.box{half_extents = {%g, %g, %g}}", d->half_extents.x, d->half_extents.y, d->half_extents.z);
        break;
    case CAROM_SHAPE_CAPSULE: snprintf(buf, sizeof buf, "carom.capsule{radius = %g, half_height = %g}", d->radius, d->half_height); break;
    case CAROM_SHAPE_CYLINDER: snprintf(buf, sizeof buf, "carom.cylinder{radius = %g, half_height = %g}", d->radius, d->half_height); break;
    case CAROM_SHAPE_HULL: snprintf(buf, sizeof buf, "carom.hull{%d points}", d->point_count); break;
    case CAROM_SHAPE_MESH: {
        const clua_shape *s = lua_touserdata(L, 1);
        snprintf(buf, sizeof buf, "carom.mesh{%d vertices, %d triangles}", s->mesh.vertex_count, s->mesh.triangle_count);
        break;
    }
    case CAROM_SHAPE_HEIGHTFIELD: {
        const clua_shape *s = lua_touserdata(L, 1);
        snprintf(buf, sizeof buf, "carom.heightfield{%d x %d, cell = {%g, %g}}", s->heightfield.rows,
                 s->heightfield.columns, s->heightfield.cell_x, s->heightfield.cell_y);
        break;
    }
    case CAROM_SHAPE_COMPOUND:
        snprintf(buf, sizeof buf, "carom.compound{%d children}", ((const clua_shape *)lua_touserdata(L, 1))->child_count);
        break;
    default:
        snprintf(buf, sizeof buf, "carom.plane{normal = {%g, %g, %g}, offset = %g}", d->normal.x, d->normal.y, d->normal.z, d->offset);
        break;
    }
    lua_pushstring(L, buf);
    return 1;
}

static int vec_eq(carom_vec3 a, carom_vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/* Two descriptors are equal when they describe the same shape. */
static int shape_eq(lua_State *L)
{
    clua_shape *a = luaL_testudata(L, 1, CLUA_SHAPE_MT), *b = luaL_testudata(L, 2, CLUA_SHAPE_MT);
    int same = a && b && a->def.type == b->def.type;
    if (same) {
        const carom_shape_def *p = &a->def, *q = &b->def;
        switch (p->type) {
        case CAROM_SHAPE_SPHERE: same = p->radius == q->radius; break;
        case CAROM_SHAPE_BOX: same = vec_eq(p->half_extents, q->half_extents); break;
        case CAROM_SHAPE_CAPSULE:
        case CAROM_SHAPE_CYLINDER: same = p->radius == q->radius && p->half_height == q->half_height; break;
        case CAROM_SHAPE_HULL:
            same = p->point_count == q->point_count &&
                   (p->point_count == 0 || memcmp(p->points, q->points, sizeof(double) * 3 * (size_t)p->point_count) == 0);
            break;
        case CAROM_SHAPE_MESH:
        case CAROM_SHAPE_HEIGHTFIELD:
        case CAROM_SHAPE_COMPOUND: same = a == b; break; /* the same descriptor */
        default: same = vec_eq(p->normal, q->normal) && p->offset == q->offset; break;
        }
    }
    lua_pushboolean(L, same);
    return 1;
}

/* shape.type, .radius, .half_height, .half_extents, .normal, .offset, .point_count (read only) */
static int shape_index(lua_State *L)
{
    const carom_shape_def *d = &((clua_shape *)luaL_checkudata(L, 1, CLUA_SHAPE_MT))->def;
    const char *k = lua_tostring(L, 2);
    if (lua_type(L, 2) != LUA_TSTRING) lua_pushnil(L);
    else if (strcmp(k, "type") == 0) lua_pushstring(L, clua_shape_names[d->type]);
    else if (strcmp(k, "radius") == 0 && (d->type == CAROM_SHAPE_SPHERE || d->type == CAROM_SHAPE_CAPSULE || d->type == CAROM_SHAPE_CYLINDER))
        lua_pushnumber(L, d->radius);
    else if (strcmp(k, "half_height") == 0 && (d->type == CAROM_SHAPE_CAPSULE || d->type == CAROM_SHAPE_CYLINDER))
        lua_pushnumber(L, d->half_height);
    else if (strcmp(k, "half_extents") == 0 && d->type == CAROM_SHAPE_BOX) clua_push_vec3_table(L, d->half_extents);
    else if (strcmp(k, "normal") == 0 && d->type == CAROM_SHAPE_PLANE) clua_push_vec3_table(L, d->normal);
    else if (strcmp(k, "offset") == 0 && d->type == CAROM_SHAPE_PLANE) lua_pushnumber(L, d->offset);
    else if (strcmp(k, "point_count") == 0 && d->type == CAROM_SHAPE_HULL) lua_pushinteger(L, d->point_count);
    else lua_pushnil(L);
    return 1;
}

static int shape_newindex(lua_State *L)
{
    return luaL_error(L, "shapes are immutable: make a new one (carom.%s{...})",
                      clua_shape_names[((clua_shape *)luaL_checkudata(L, 1, CLUA_SHAPE_MT))->def.type]);
}

void clua_open_shapes(lua_State *L)
{
    static const luaL_Reg meta[] = {{"__gc", shape_gc}, {"__tostring", shape_tostring}, {"__eq", shape_eq},
                                    {"__index", shape_index}, {"__newindex", shape_newindex}, {NULL, NULL}};
    static const luaL_Reg constructors[] = {{"sphere", l_sphere}, {"box", l_box}, {"capsule", l_capsule},
                                            {"cylinder", l_cylinder}, {"hull", l_hull}, {"plane", l_plane},
                                            {"mesh", l_mesh}, {"heightfield", l_heightfield}, {"compound", l_compound},
                                            {NULL, NULL}};
    luaL_newmetatable(L, CLUA_SHAPE_MT);
    luaL_setfuncs(L, meta, 0);
    lua_pushliteral(L, "locked");
    lua_setfield(L, -2, "__metatable");
    lua_pop(L, 1);
    luaL_setfuncs(L, constructors, 0);
}
