/* floor: scene */
/* The transfer names (core/transfer_kind.c): each name the scene file takes
 * means its kind, every kind has its name, and the scene reader and its
 * message follow the table. The expected pairs are written out here, as the
 * papers name them, so a table that pairs a name with the wrong kind fails. */
#include <string.h>

#include "core/error.h"
#include "core/scene/scene_load.h"
#include "core/transfer.h"
#include "tests/common/testutil.h"

static const struct {
    const char *name;
    TransferKind kind;
} expected[] = {{"apic", TRANSFER_APIC}, {"mls", TRANSFER_MLS}, {"pic_flip", TRANSFER_PIC_FLIP}};
enum { N_EXPECTED = sizeof expected / sizeof expected[0] };

static void names_and_kinds(void)
{
    int n = 0;
    while (transfer_names[n]) ++n;
    CHECK(n == N_EXPECTED, "%d names, expected %d", n, N_EXPECTED);
    for (int i = 0; i < N_EXPECTED; ++i) {
        TransferKind k = (TransferKind)-1;
        CHECK(transfer_kind_from_name(expected[i].name, &k) && k == expected[i].kind, "%s names kind %d (got %d)",
              expected[i].name, (int)expected[i].kind, (int)k);
        CHECK(!strcmp(transfer_kind_name(expected[i].kind), expected[i].name), "kind %d is called %s, not %s",
              (int)expected[i].kind, expected[i].name, transfer_kind_name(expected[i].kind));
    }
    TransferKind k;
    CHECK(!transfer_kind_from_name("flip", &k) && !transfer_kind_from_name("", &k), "unknown names refused");
}

/* The scene reader takes every name, and its message for a bad one lists them all. */
static void scene_reader(void)
{
    Scene s;
    for (int i = 0; transfer_names[i]; ++i) {
        SceneOverride o[] = {{"transfer", transfer_names[i]}};
        SceneLoadOptions lo = {.scale = 4.0, .overrides = o, .n_overrides = 1};
        mpm_clear_error();
        int st = scene_load("drop", &lo, &s);
        TransferKind k = (TransferKind)-1;
        transfer_kind_from_name(transfer_names[i], &k);
        CHECK(st == MPM_OK && s.transfer == k, "transfer %s: %s", transfer_names[i], mpm_last_error());
        if (!st) scene_free(&s);
    }
    SceneOverride bad[] = {{"transfer", "flip"}};
    SceneLoadOptions lo = {.scale = 4.0, .overrides = bad, .n_overrides = 1};
    mpm_clear_error();
    int st = scene_load("drop", &lo, &s);
    const char *msg = mpm_last_error();
    CHECK(st == MPM_EINPUT &&
              strstr(msg, "transfer: expected \"apic\", \"mls\", \"pic_flip\" or {\"type\": \"pic_flip\", \"alpha\": a}"),
          "message: %s", msg);
    if (!st) scene_free(&s);
}

int main(void)
{
    names_and_kinds();
    scene_reader();
    return test_summary("test_transfer_kind");
}
