/* floor: scene */
/* The scene file's key tables (core/scene/scene_keys.c) and the reader
 * agree, level by level (the top, a material, its plasticity, an object, a
 * collider, a source):
 *  - a scene of only the keys the tables call required loads, so every
 *    other key may be absent; without any one of them it fails with
 *    "PATH: missing required field";
 *  - --set adds every key a table lets be absent (whatever the reader then
 *    says of the value, not "does not exist") and refuses an unknown key;
 *  - an unknown key is refused with the table's keys, in table order, and
 *    a key of another variant (plasticity "type") with the variant's;
 * and the tables are what docs/scenes.md documents: the same keys in each
 * section's table, the same required ones, the same keys per plasticity
 * type. */
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/scene/scene_keys.h"
#include "core/scene/scene_load.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

/* Every required key at every level, and one collider and one source (the
 * top level's optional "colliders" and "sources") to reach their levels. */
static const char *const minimal =
    "{\"name\": \"keys\", \"dx\": 0.05, \"fps\": 24, \"frames\": 1, \"gravity\": [0, -9.8, 0],"
    " \"domain\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},"
    " \"materials\": {\"soft\": {\"E\": 1e4, \"nu\": 0.3, \"density\": 1000, \"plasticity\": {\"type\": \"none\"}}},"
    " \"objects\": [{\"material\": \"soft\", \"shape\": {\"type\": \"box\", \"min\": [0.4, 0.4, 0.4],"
    " \"max\": [0.6, 0.6, 0.6]}, \"ppc\": 1}],"
    " \"colliders\": [{\"shape\": {\"type\": \"half_space\", \"point\": [0, 0.1, 0], \"normal\": [0, 1, 0]}}],"
    " \"sources\": [{\"material\": \"soft\", \"shape\": {\"type\": \"sphere\", \"center\": [0.5, 0.8, 0.5],"
    " \"radius\": 0.05}, \"ppc\": 1, \"velocity\": [0, -1, 0]}]}";

typedef struct {
    const char *path;      /* the object's JSON path in the minimal scene ("" = the top level) */
    const SceneKey *keys;
    unsigned variant;      /* the variant the minimal scene has (0: the object has none) */
    const char *extra;     /* an optional key the minimal scene has anyway, NULL: none */
    const char *extra2;
} Level;

static const Level levels[] = {
    {"", scene_top_keys, 0, "colliders", "sources"},
    {"materials.soft", scene_material_keys, 0, "plasticity", NULL},
    {"materials.soft.plasticity", scene_plasticity_keys, SCENE_PLASTICITY_NONE, NULL, NULL},
    {"objects.0", scene_object_keys, 0, NULL, NULL},
    {"colliders.0", scene_collider_keys, 0, NULL, NULL},
    {"sources.0", scene_source_keys, 0, NULL, NULL},
};
enum { N_LEVELS = sizeof levels / sizeof levels[0] };

/* The object at a dot path of root ("objects.0.shape"). */
static json_t *at(json_t *root, const char *path)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", path);
    json_t *cur = root;
    for (char *tok = strtok(buf, "."); tok && cur; tok = strtok(NULL, "."))
        cur = json_is_array(cur) ? json_array_get(cur, (size_t)atoi(tok)) : json_object_get(cur, tok);
    return cur;
}

static void join(const char *path, const char *key, char *out, size_t n)
{
    snprintf(out, n, "%s%s%s", path, path[0] ? "." : "", key);
}

/* Loads the scene text with one --set (key NULL: none); MPM_OK or the status, the message in msg. */
static int load(const char *text, const char *key, const char *value, char *msg, size_t n)
{
    Scene s;
    const char *set[2] = {key, value};
    mpm_clear_error();
    int st = test_scene_from_text(text, 1.0, set, key ? 1 : 0, &s);
    snprintf(msg, n, "%s", st ? mpm_last_error() : "");
    if (!st) scene_free(&s);
    return st;
}

static void required_keys(void)
{
    char msg[1024];
    CHECK(load(minimal, NULL, NULL, msg, sizeof msg) == MPM_OK, "the scene of required keys loads: %s", msg);
    json_t *root = json_loads(minimal, 0, NULL);
    CHECK(root != NULL, "the test's scene is JSON");
    if (!root) return;
    for (int l = 0; l < N_LEVELS; ++l) {
        const Level *lv = &levels[l];
        json_t *obj = at(root, lv->path);
        /* the minimal scene has exactly the required keys (and the extras that lead to other levels) */
        const char *key;
        json_t *v;
        json_object_foreach(obj, key, v) {
            int extra = (lv->extra && !strcmp(key, lv->extra)) || (lv->extra2 && !strcmp(key, lv->extra2));
            CHECK(extra || !scene_key_optional(lv->keys, key), "%s.%s: in the scene of required keys, but optional",
                  lv->path, key);
        }
        for (const SceneKey *k = lv->keys; k->name; ++k) {
            if (k->optional) continue;
            CHECK(json_object_get(obj, k->name) != NULL, "%s: required key %s missing from the test's scene", lv->path,
                  k->name);
            json_t *copy = json_deep_copy(root);
            json_object_del(at(copy, lv->path), k->name);
            char *text = json_dumps(copy, 0);
            char where[256], want[300];
            join(lv->path, k->name, where, sizeof where);
            snprintf(want, sizeof want, ": %s: missing required field", where);
            int st = load(text, NULL, NULL, msg, sizeof msg);
            CHECK(st == MPM_EINPUT && strstr(msg, want), "without %s: %s", where, msg);
            free(text);
            json_decref(copy);
        }
    }
    json_decref(root);
}

static void set_adds_optional_keys(void)
{
    char msg[1024], where[256];
    for (int l = 0; l < N_LEVELS; ++l) {
        const Level *lv = &levels[l];
        for (const SceneKey *k = lv->keys; k->name; ++k) {
            if (!k->optional || (lv->extra && !strcmp(k->name, lv->extra)) ||
                (lv->extra2 && !strcmp(k->name, lv->extra2)))
                continue;
            join(lv->path, k->name, where, sizeof where);
            load(minimal, where, "1", msg, sizeof msg);
            CHECK(!strstr(msg, "does not exist"), "--set %s=1 adds the key: %s", where, msg);
        }
        join(lv->path, "no_such_key", where, sizeof where);
        int st = load(minimal, where, "1", msg, sizeof msg);
        CHECK(st == MPM_EINPUT && strstr(msg, "does not exist"), "--set %s=1 refused: %s", where, msg);
    }
}

/* The scene with `key` added at the level's path is refused, the message
 * listing the keys of `variant` (0: every key) in table order. */
static void refused_listing(json_t *root, const Level *lv, const char *key, unsigned variant)
{
    char msg[1024], want[1024], where[256];
    json_t *copy = json_deep_copy(root);
    json_object_set_new(at(copy, lv->path), key, json_integer(1));
    char *text = json_dumps(copy, 0);
    join(lv->path, key, where, sizeof where);
    size_t len = (size_t)snprintf(want, sizeof want, "%s: unknown key (known: ", where);
    int n = 0;
    for (const SceneKey *k = lv->keys; k->name; ++k)
        if (!variant || !k->only || (k->only & variant))
            len += (size_t)snprintf(want + len, sizeof want - len, "%s%s", n++ ? ", " : "", k->name);
    snprintf(want + len, sizeof want - len, ")");
    int st = load(text, NULL, NULL, msg, sizeof msg);
    CHECK(st == MPM_EINPUT && strstr(msg, want), "%s: %s (wanted ...%s)", where, msg, want);
    free(text);
    json_decref(copy);
}

static void unknown_keys_listed(void)
{
    json_t *root = json_loads(minimal, 0, NULL);
    if (!root) return;
    for (int l = 0; l < N_LEVELS; ++l) {
        const Level *lv = &levels[l];
        refused_listing(root, lv, "no_such_key", 0);
        for (const SceneKey *k = lv->keys; lv->variant && k->name; ++k)
            if (k->only && !(k->only & lv->variant)) refused_listing(root, lv, k->name, lv->variant);
    }
    json_decref(root);
}

/* ------------------------------------------------------------------ docs */

static char *read_doc(void)
{
    char path[1024];
    const char *slash = strrchr(__FILE__, '/');
    snprintf(path, sizeof path, "%.*s/../../docs/scenes.md", slash ? (int)(slash - __FILE__) : 1, slash ? __FILE__ : ".");
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    static char text[1 << 18];
    size_t n = fread(text, 1, sizeof text - 1, f);
    text[n] = '\0';
    fclose(f);
    return text;
}

typedef struct {
    char key[32][32];
    char rest[32][512];   /* the row after its first cell */
    int n;
} DocRows;

/* The rows of the table under `heading`, up to the next heading; each row's
 * first cell may name several keys (`from`, `until`). */
static void doc_rows(const char *doc, const char *heading, DocRows *rows)
{
    rows->n = 0;
    const char *p = strstr(doc, heading);
    if (!p) return;
    p = strchr(p, '\n');
    while (p && *++p && *p != '#') {
        const char *eol = strchr(p, '\n');
        size_t len = eol ? (size_t)(eol - p) : strlen(p);
        if (!strncmp(p, "| `", 3)) {
            const char *bar = memchr(p + 1, '|', len - 1);
            for (const char *q = p + 1; bar && q < bar && rows->n < 32;) {
                const char *a = memchr(q, '`', (size_t)(bar - q)), *b = a ? memchr(a + 1, '`', (size_t)(bar - a - 1)) : NULL;
                if (!b) break;
                snprintf(rows->key[rows->n], sizeof rows->key[0], "%.*s", (int)(b - a - 1), a + 1);
                snprintf(rows->rest[rows->n++], sizeof rows->rest[0], "%.*s", (int)(len - (size_t)(bar + 1 - p)), bar + 1);
                q = b + 1;
            }
        }
        p = eol;
    }
}

static const char *doc_row(const DocRows *rows, const char *key)
{
    for (int i = 0; i < rows->n; ++i)
        if (!strcmp(rows->key[i], key)) return rows->rest[i];
    return NULL;
}

/* A row says its key is required: the top level's column ("| yes |"), or a meaning that starts so. */
static int doc_required(const char *rest)
{
    while (*rest == ' ') ++rest;
    return !strncmp(rest, "yes", 3) || !strncmp(rest, "required", 8);
}

static void documented(void)
{
    const char *doc = read_doc();
    CHECK(doc != NULL, "docs/scenes.md readable");
    if (!doc) return;
    static const struct {
        const char *heading;
        const SceneKey *keys;
        int marks_required; /* the section says which keys are required */
    } sections[] = {{"### 2.1 Top-level fields", scene_top_keys, 1},
                    {"### 2.2 Materials", scene_material_keys, 0},
                    {"### 2.3 Objects", scene_object_keys, 1},
                    {"### 2.5 Colliders", scene_collider_keys, 1},
                    {"### 2.6 Particle sources", scene_source_keys, 1}};
    for (size_t s = 0; s < sizeof sections / sizeof sections[0]; ++s) {
        DocRows rows;
        doc_rows(doc, sections[s].heading, &rows);
        CHECK(rows.n > 0, "%s: a table of fields", sections[s].heading);
        for (const SceneKey *k = sections[s].keys; k->name; ++k) {
            const char *rest = doc_row(&rows, k->name);
            CHECK(rest != NULL, "%s: key %s not documented", sections[s].heading, k->name);
            if (rest && sections[s].marks_required)
                CHECK(doc_required(rest) == !k->optional, "%s: %s is %s in the table, not in the docs",
                      sections[s].heading, k->name, k->optional ? "optional" : "required");
        }
        for (int i = 0; i < rows.n; ++i) {
            int known = 0;
            for (const SceneKey *k = sections[s].keys; k->name; ++k) known |= !strcmp(k->name, rows.key[i]);
            CHECK(known, "%s: documented key %s not in the table", sections[s].heading, rows.key[i]);
        }
    }
    /* the plasticity row: {"type": "NAME", "key": value, ...} per type */
    static const struct {
        const char *type;
        unsigned variant;
    } types[] = {{"none", SCENE_PLASTICITY_NONE}, {"von_mises", SCENE_PLASTICITY_VON_MISES}, {"snow", SCENE_PLASTICITY_SNOW}};
    DocRows rows;
    doc_rows(doc, "### 2.2 Materials", &rows);
    const char *row = doc_row(&rows, "plasticity");
    for (size_t t = 0; row && t < sizeof types / sizeof types[0]; ++t) {
        char open[64];
        snprintf(open, sizeof open, "{\"type\": \"%s\"", types[t].type);
        const char *p = strstr(row, open), *end = p ? strchr(p, '}') : NULL;
        CHECK(end != NULL, "the plasticity row documents type %s", types[t].type);
        if (!end) continue;
        int n_doc = 0, n_table = 0;
        for (const char *a = strchr(p, '"'); a && a < end;) { /* a quoted text followed by ':' is a key */
            const char *b = strchr(a + 1, '"');
            if (!b || b > end) break;
            if (b[1] == ':') {
                char key[32];
                snprintf(key, sizeof key, "%.*s", (int)(b - a - 1), a + 1);
                int in_variant = 0;
                for (const SceneKey *k = scene_plasticity_keys; k->name; ++k)
                    in_variant |= !strcmp(k->name, key) && (!k->only || (k->only & types[t].variant));
                CHECK(in_variant, "plasticity %s: documented key %s not in its variant", types[t].type, key);
                ++n_doc;
            }
            a = strchr(b + 1, '"');
        }
        for (const SceneKey *k = scene_plasticity_keys; k->name; ++k) n_table += !k->only || (k->only & types[t].variant);
        CHECK(n_doc == n_table, "plasticity %s: %d keys documented, %d in its variant", types[t].type, n_doc, n_table);
    }
}

int main(void)
{
    required_keys();
    set_adds_optional_keys();
    unknown_keys_listed();
    documented();
    return test_summary("test_scene_keys");
}
