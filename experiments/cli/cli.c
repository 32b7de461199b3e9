/* The command-line parser and the usage text (cli.h). */
#include "experiments/cli/cli.h"

#include <string.h>

#include "core/error.h"

static int group_size(const OptionGroup *g)
{
    if (g->n > 0) return g->n;
    int n = 0;
    while (g->table[n].flag) ++n;
    return n;
}

static int taken(const OptionGroup *g, const char *flag)
{
    if (!g->only) return 1;
    for (int i = 0; g->only[i]; ++i)
        if (!strcmp(g->only[i], flag)) return 1;
    return 0;
}

/* The group and index of flag in cmd, 0 when it has none. */
static int locate(const Command *cmd, const char *flag, int *group, int *index)
{
    for (int gi = 0; gi < cmd->n_groups; ++gi) {
        const OptionGroup *g = &cmd->groups[gi];
        int k = option_find_flag(g->table, group_size(g), flag);
        if (k >= 0 && taken(g, flag)) {
            *group = gi;
            *index = k;
            return 1;
        }
    }
    return 0;
}

const Option *cli_find(const Command *cmd, const char *flag, size_t *base)
{
    int gi, k;
    if (!locate(cmd, flag, &gi, &k)) return NULL;
    if (base) *base = cmd->groups[gi].base;
    return &cmd->groups[gi].table[k];
}

int cli_takes_operand(const Command *cmd) { return cmd->operand || cmd->operand_choices; }

/* The operand's name in the usage ("FILE", "spmv|hessvec|...|all"). */
static void operand_name(const Command *cmd, char *out, size_t n)
{
    size_t len = (size_t)snprintf(out, n, "%s", cmd->operand ? cmd->operand : "");
    for (int k = 0; !cmd->operand && cmd->operand_choices && cmd->operand_choices[k] && len < n; ++k)
        len += (size_t)snprintf(out + len, n - len, "%s%s", k ? "|" : "", cmd->operand_choices[k]);
}

/* What a message says the operand should be ("a matrix file", "spmv, hessvec, ... or all"). */
static void operand_expected(const Command *cmd, char *out, size_t n)
{
    size_t len = (size_t)snprintf(out, n, "%s", cmd->operand_missing ? cmd->operand_missing : "");
    int count = 0;
    while (!cmd->operand_missing && cmd->operand_choices && cmd->operand_choices[count]) ++count;
    for (int k = 0; k < count && len < n; ++k)
        len += (size_t)snprintf(out + len, n - len, "%s%s", k == 0 ? "" : k + 1 == count ? " or " : ", ",
                                cmd->operand_choices[k]);
}

static int is_help(const char *a) { return !strcmp(a, "-h") || !strcmp(a, "--help"); }

int cli_parse(const Command *cmd, int argc, char **argv, int first, void *args, const char **operand, int *help)
{
    if (cmd->args_size) memset(args, 0, cmd->args_size); /* a command without options has no args struct */
    if (cmd->init) cmd->init(args);
    *operand = NULL;
    *help = 0;
    for (int i = first; i < argc; ++i)
        if (is_help(argv[i])) {
            *help = 1;
            return MPM_OK;
        }
    unsigned long long given[CLI_MAX_GROUPS] = {0}; /* bit k of group g: its option k was given */
    int only_operands = 0;
    char name[512], expected[512];
    operand_name(cmd, name, sizeof name);
    operand_expected(cmd, expected, sizeof expected);
    for (int i = first; i < argc; ++i) {
        const char *a = argv[i];
        if (!only_operands && !strcmp(a, "--")) {
            only_operands = 1;
            continue;
        }
        if (only_operands || a[0] != '-' || !a[1]) { /* an operand */
            if (!cli_takes_operand(cmd))
                return mpm_error(MPM_EINPUT, "%s: unexpected argument '%s' (see: mpmbench %s --help)", cmd->name, a,
                                 cmd->name);
            if (*operand)
                return mpm_error(MPM_EINPUT, "%s: one %s expected, got '%s' and '%s' (see: mpmbench %s --help)", cmd->name,
                                 name, *operand, a, cmd->name);
            *operand = a;
            continue;
        }
        /* --flag=value or --flag value */
        char flag[64];
        const char *eq = strncmp(a, "--", 2) == 0 ? strchr(a, '=') : NULL;
        const char *value = NULL;
        if (eq) {
            snprintf(flag, sizeof flag, "%.*s", (int)(eq - a < 63 ? eq - a : 63), a);
            value = eq + 1;
        } else {
            snprintf(flag, sizeof flag, "%s", a);
        }
        int gi, k;
        if (!locate(cmd, flag, &gi, &k))
            return mpm_error(MPM_EINPUT, "%s: unknown option '%s' (see: mpmbench %s --help)", cmd->name, flag, cmd->name);
        const Option *o = &cmd->groups[gi].table[k];
        void *target = (char *)args + cmd->groups[gi].base;
        OptionValue v;
        memset(&v, 0, sizeof v);
        if (o->type == OPT_SWITCH) {
            if (value) return mpm_error(MPM_EINPUT, "%s takes no value (got '%s')", flag, value);
            v.i = 1;
        } else {
            if (!value) {
                if (i + 1 >= argc) return mpm_error(MPM_EINPUT, "%s: missing value", flag);
                value = argv[++i];
            }
            int st = option_parse_text(o, value, &v);
            if (st) return st;
        }
        int st = option_set(o, target, &v);
        if (st) return st;
        if (k < 64) given[gi] |= 1ull << k;
    }
    if (cli_takes_operand(cmd) && !*operand)
        return mpm_error(MPM_EINPUT, "%s: expected %s (see: mpmbench %s --help)", cmd->name, expected, cmd->name);
    if (cmd->operand_choices) {
        int ok = 0;
        for (int k = 0; cmd->operand_choices[k] && !ok; ++k) ok = !strcmp(*operand, cmd->operand_choices[k]);
        if (!ok) return mpm_error(MPM_EINPUT, "%s '%s': expected %s", cmd->name, *operand, expected);
    }
    for (int r = 0; cmd->required && cmd->required[r]; ++r) {
        int gi, k;
        int found = locate(cmd, cmd->required[r], &gi, &k) && k < 64 && (given[gi] >> k & 1);
        if (!found) return mpm_error(MPM_EINPUT, "%s: %s is required", cmd->name, cmd->required[r]);
    }
    return MPM_OK;
}

#define USAGE_WIDTH 100
#define USAGE_COLUMN 30

void cli_wrap(FILE *f, int col, int at, const char *text)
{
    /* words go on while the line stays within USAGE_WIDTH; a new line starts at col */
    while (*text) {
        while (*text == ' ') ++text;
        size_t word = strcspn(text, " ");
        if (!word) break;
        if (at > col && at + 1 + (int)word > USAGE_WIDTH) {
            fprintf(f, "\n%*s", col, "");
            at = col;
        } else if (at > col) {
            fputc(' ', f);
            ++at;
        }
        fprintf(f, "%.*s", (int)word, text);
        at += (int)word;
        text += word;
    }
    fputc('\n', f);
}

/* "  --flag VALUE" padded to a column, then the help and the allowed values. */
static void usage_line(const Option *o, int show_key, FILE *f)
{
    char head[96], want[256], text[1024], value[64];
    option_metavar(o, value, sizeof value);
    snprintf(head, sizeof head, "  %s%s%s", o->flag, value[0] ? " " : "", value);
    fprintf(f, "%-*s", USAGE_COLUMN, head);
    if ((int)strlen(head) >= USAGE_COLUMN) fprintf(f, "\n%*s", USAGE_COLUMN, "");
    size_t len = (size_t)snprintf(text, sizeof text, "%s", o->help);
    if ((o->type == OPT_INT || o->type == OPT_REAL || o->type == OPT_SIZE) && len < sizeof text) {
        option_expect(o, 0, want, sizeof want);
        len += (size_t)snprintf(text + len, sizeof text - len, "; %s", want);
    }
    if (show_key && o->key && len < sizeof text) snprintf(text + len, sizeof text - len, " [matrix key: %s]", o->key);
    cli_wrap(f, USAGE_COLUMN, USAGE_COLUMN, text);
}

void cli_synopsis(const Command *cmd, FILE *f)
{
    fprintf(f, "mpmbench %s", cmd->name);
    char name[512];
    operand_name(cmd, name, sizeof name);
    if (cli_takes_operand(cmd)) fprintf(f, " %s", name);
    for (int r = 0; cmd->required && cmd->required[r]; ++r) {
        const Option *o = cli_find(cmd, cmd->required[r], NULL);
        char value[64] = "";
        if (o) option_metavar(o, value, sizeof value);
        fprintf(f, " %s%s%s", cmd->required[r], value[0] ? " " : "", value);
    }
    if (cmd->n_groups) fprintf(f, " [options]");
}

void cli_usage(const Command *cmd, FILE *f)
{
    fprintf(f, "usage: ");
    cli_synopsis(cmd, f);
    fprintf(f, "\n\n");
    cli_wrap(f, 0, 0, cmd->summary);
    for (int gi = 0; gi < cmd->n_groups; ++gi) {
        const OptionGroup *g = &cmd->groups[gi];
        fprintf(f, "\n%s:\n", g->title ? g->title : "options");
        for (int k = 0; k < group_size(g); ++k)
            if (taken(g, g->table[k].flag)) usage_line(&g->table[k], g->show_keys, f);
    }
    fprintf(f, "\n%-*s%s\n", USAGE_COLUMN, "  -h, --help", "this help");
    fprintf(f, "\nA value follows its flag as --flag VALUE or --flag=VALUE.\n");
    if (cmd->notes) fprintf(f, "\n%s", cmd->notes);
}
