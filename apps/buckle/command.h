// Shared plumbing of the buckle subcommands.
//
// A subcommand registers itself on the CLI11 application and, when it runs, stores its exit
// status in the Outcome: 0 success, 2 bad input (the message names the argument), 1 computation
// failure. main() turns CLI11 parse errors into status 2 as well.
#pragma once

#include <string>

namespace buckle::cli {

enum ExitCode : int { kSuccess = 0, kComputationFailure = 1, kBadInput = 2 };

struct Outcome {
  int code = kSuccess;
};

/// Thrown by a subcommand for an invalid argument value; main() prints "error: <message>" and
/// exits with kBadInput. The message starts with the argument name (e.g. "--b must be > 0").
struct BadArgument {
  std::string message;
};

}  // namespace buckle::cli
