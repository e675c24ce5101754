// The facet executable: the CLI itself is facet::cli::run (cli/main.cpp), which the hostile-input
// suite also calls in forked children.
#include "cli/command.hpp"

int main(int argc, char** argv) { return facet::cli::run(argc, argv); }
