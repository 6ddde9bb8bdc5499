// The `apparent` command. Only main decides to stop; everything else returns a status.
#include <iostream>

#include "pipeline/cli.h"

int main(int argc, char** argv) { return apparent::runCommandLine(argc, argv, std::cout, std::cerr); }
