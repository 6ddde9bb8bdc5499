// The `apparent` command. Only main decides to stop; everything else returns a status.
#include <iostream>

#include "exporters/atomic_file.h"
#include "pipeline/cli.h"

int main(int argc, char** argv) {
    // Ctrl-C or SIGTERM: remove the temporary files in progress, exit 130 or 143 (atomic_file.h).
    apparent::installInterruptCleanup();
    return apparent::runCommandLine(argc, argv, std::cout, std::cerr);
}
