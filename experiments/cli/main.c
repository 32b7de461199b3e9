/* mpmbench: the program is cli_main (experiments/cli/commands.h). */
#include "experiments/cli/commands.h"

int main(int argc, char **argv) { return cli_main(argc, argv); }
