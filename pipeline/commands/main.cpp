// The `apparent` command. Only main decides to stop; everything else returns a status.
#include <cstring>
#include <fcntl.h>
#ifdef __GLIBC__
#include <malloc.h>  // mallopt
#endif
#include <unistd.h>
#include <iostream>
#include <sstream>

#include "exporters/atomic_file.h"
#include "pipeline/commands/cli.h"
#ifdef APPARENT_HAVE_MPI
#include "pipeline/run/mpi_group.h"
#endif

namespace {

// Freed memory the process keeps for its next allocations, bytes: a frame's buffers (tens of MB
// at 1M triangles) are reused in place frame after frame instead of unmapped and faulted in again
// zero-filled (glibc's defaults map a block that large on its own and trim a heap whose free top
// passes 128 kB; docs/PERFORMANCE.md, issue 37). More than this is given back, so one huge frame
// does not hold its memory for the program's life (the budget of the cut's RefineScratch).
constexpr int kFreedMemoryKeep = 256 << 20;

void keepFreedMemory() {
#ifdef __GLIBC__
    ::mallopt(M_MMAP_THRESHOLD, kFreedMemoryKeep);
    ::mallopt(M_TRIM_THRESHOLD, kFreedMemoryKeep);
#endif
}

}  // namespace

int main(int argc, char** argv) {
    keepFreedMemory();
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
