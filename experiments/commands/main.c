/* mpmbench: the program is cli_main (experiments/commands/commands.h). */
#include "experiments/commands/commands.h"

int main(int argc, char **argv) { return cli_main(argc, argv); }
