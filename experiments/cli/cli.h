/* The one command-line parser of mpmbench. Every command (run, list, bench,
 * render, matrix run, matrix report) is a Command: its operands and its
 * option groups, each a table of options (options.h) or a part of one (the
 * run settings a command takes). The parser and the --help text come from
 * these tables alone.
 *
 * Conventions, the same for every command:
 *   --flag value and --flag=value; a switch takes no value;
 *   -h / --help prints the command's usage on stdout (exit 0);
 *   an unknown option, a missing or bad value, a missing operand: one line
 *   naming the option and the value, exit 2 (MPM_EINPUT). */
#ifndef MPM_CLI_H
#define MPM_CLI_H

#include <stddef.h>
#include <stdio.h>

#include "experiments/cli/options.h"

/* Options of a table, in a command's argument struct at `base`. */
typedef struct {
    const Option *table;
    int n;                       /* entries; 0: up to the entry whose flag is NULL */
    const char *const *only;     /* NULL-terminated flags to take from the table; NULL: every entry */
    size_t base;                 /* offset of the table's target struct in the command's arguments */
    const char *title;           /* heading in the help ("run settings"), NULL: "options" */
    int show_keys;               /* the help names each option's matrix-file key */
} OptionGroup;

#define CLI_MAX_GROUPS 3

/* Exit statuses of mpmbench (main, the usage text and the README say them). */
enum { CLI_EXIT_OK = 0, CLI_EXIT_INTERNAL = 1, CLI_EXIT_INPUT = 2, CLI_EXIT_CHECK_FAILED = 3 };

typedef struct Command {
    const char *name;            /* "run", "matrix run" */
    const char *operand;         /* the operand's name in the usage ("FILE"); NULL: its choices joined
                                    by '|', or no operand when it has no choices either */
    const char *const *operand_choices; /* allowed operands (NULL-terminated), NULL: any text */
    const char *operand_missing; /* what the message says is missing: "a matrix file"; NULL: its
                                    choices as "a, b or c" */
    const char *summary;         /* one line: what the command does */
    const char *notes;           /* more lines after the options (NULL: none) */
    const char *const *required; /* flags that must be given (NULL-terminated), NULL: none */
    OptionGroup groups[CLI_MAX_GROUPS];
    int n_groups;
    size_t args_size;            /* the argument struct */
    /* sets the defaults of args (NULL: all zero) */
    void (*init)(void *args);
    /* runs the command: an MPM_* status; *exit_code may be set to a
     * successful run's other exit status (CLI_EXIT_CHECK_FAILED) */
    int (*run)(void *args, const char *operand, int *exit_code);
} Command;

/* Parses argv[first..argc) for cmd into args (initialised by cmd->init);
 * *operand gets the operand (NULL when the command has none). *help is set
 * when -h or --help was given (nothing else is checked then). */
int cli_parse(const Command *cmd, int argc, char **argv, int first, void *args, const char **operand, int *help);

/* The command's usage, generated from its tables; its one-line synopsis
 * ("mpmbench run --scene NAME|FILE --solver SPEC [options]"). */
void cli_usage(const Command *cmd, FILE *f);
void cli_synopsis(const Command *cmd, FILE *f);
/* text as words from column `at` on, wrapping to lines that start at column col. */
void cli_wrap(FILE *f, int col, int at, const char *text);

/* Does cmd take an operand? */
int cli_takes_operand(const Command *cmd);

/* The option a flag names in cmd, NULL when none (for tests). */
const Option *cli_find(const Command *cmd, const char *flag, size_t *base);

#endif
