/* `mpmbench matrix run FILE`, `mpmbench matrix report DIR` and `mpmbench
 * matrix schema`: the commands (experiments/cli/cli.h) of the
 * experiment-matrix runner (experiments/matrix/matrix_run.h), of its report
 * (scripts/matrix_report.py) and of the matrix files' JSON Schema
 * (matrix_schema.h). Their options and help are in matrix_cmd.c.
 *
 * The report runs with the first Python that can import matplotlib of
 * MPM_PYTHON (a program name looked up on PATH, or a path), the python3 on
 * PATH (so a virtual environment with matplotlib works) and the system's
 * /usr/bin/python3. The script is found at run time like the scenes
 * (core/scene/data_dir.h: share/mpmbench/scripts); MPM_SCRIPT_DIR replaces
 * its folder. */
#ifndef MPM_MATRIX_CMD_H
#define MPM_MATRIX_CMD_H

#include "experiments/cli/cli.h"

extern const Command matrix_run_command;
extern const Command matrix_report_command;
extern const Command matrix_schema_command;

#endif
