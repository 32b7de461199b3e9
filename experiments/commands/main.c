/* mpmbench: the program is cli_main (experiments/commands/commands.h), run
 * with OpenMP's wait default set first (omp_wait.h). */
#include "experiments/commands/commands.h"
#include "experiments/commands/omp_wait.h"

int main(int argc, char **argv)
{
    omp_wait_default(argv);
    return cli_main(argc, argv);
}
