// streamrt: renders a .cfg scene (docs/scene-format.md) with the stream or the recursive engine.
#include "cli/cli.h"

int main(int argc, char** argv) { return streamrt::cli::run_command(argc, argv); }
