/* The commands of mpmbench and the program's entry (experiments/commands/main.c
 * calls cli_main). The command line, the --help texts and the exit statuses
 * follow cli.h; this file lists the commands. */
#ifndef MPM_COMMANDS_H
#define MPM_COMMANDS_H

#include <stdio.h>

#include "experiments/cli/cli.h"

/* Every command, in the order of the usage; NULL-terminated. */
extern const Command *const cli_commands[];

/* The command named name ("run", "matrix run"), NULL when none. */
const Command *cli_command(const char *name);

/* The program's usage: its commands, conventions, exit statuses, environment. */
void cli_program_usage(FILE *f);

/* The whole program: parses argv, runs the command, prints a failure as one
 * line on stderr, and returns the exit status (CLI_EXIT_*). */
int cli_main(int argc, char **argv);

#endif
