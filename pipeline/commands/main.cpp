// The `apparent` command. Only main decides to stop; everything else returns a status.
#include <cstring>
#include <fcntl.h>
#include <unistd.h>
#include <iostream>
#include <sstream>

#include "exporters/atomic_file.h"
#include "pipeline/commands/cli.h"
#include "pipeline/stage/frame_cut.h"
#ifdef APPARENT_HAVE_MPI
#include "pipeline/run/mpi_group.h"
#endif

int main(int argc, char** argv) {
    apparent::keepFreedMemory();
    // Ctrl-C or SIGTERM: remove the temporary files in progress, exit 130 or 143 (atomic_file.h).
    apparent::installInterruptCleanup();
#ifdef APPARENT_HAVE_MPI
    // Under mpirun or srun: the ranks share the frames of render, raytrace and figure; rank 0 alone
    // prints and runs the other commands (pipeline/run/mpi_group.h).
    if (apparent::launchedByMpi()) {
        apparent::startMpiGroup(&argc, &argv);
        if (apparent::mpiRankZero())
            return apparent::finishMpiGroup(apparent::runCommandLine(argc, argv, std::cout, std::cerr));
        if (argc < 2 || (std::strcmp(argv[1], "render") != 0 && std::strcmp(argv[1], "raytrace") != 0 &&
                         std::strcmp(argv[1], "figure") != 0))
            return apparent::finishMpiGroup(0);
        // Not even a signal's line: mpirun reports a rank it lost, rank 0 everything else.
        if (const int null = ::open("/dev/null", O_WRONLY); null >= 0) ::dup2(null, 2);
        std::ostringstream silent;
        return apparent::finishMpiGroup(apparent::runCommandLine(argc, argv, silent, silent));
    }
#endif
    return apparent::runCommandLine(argc, argv, std::cout, std::cerr);
}
