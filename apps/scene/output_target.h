// Whether `--out DIR` may be written. An output directory is replaced as a whole when a run
// ends (output.h: StagingDirectory), so a target that holds anything the program did not write
// would be destroyed: the policy below decides, before any computation, what may be replaced.
//
//   never (not even with --force): `/`, the current directory or any directory containing it,
//     the scene file or a directory containing it, anything that is not a regular file or a
//     directory (device, socket, dangling symbolic link), a mount point;
//   always: a path that does not exist yet, an empty directory, a previous buckle output
//     (isBuckleOutput);
//   only with --force: any other directory, any other regular file.
//
// A symbolic link is followed: the policy applies to the directory it names, which is the one
// replaced (the link itself stays). The parent must be writable (checked by creating and
// removing a probe directory in the nearest existing ancestor).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace buckle::scene {

/// The `generator` marker written into summary.json by `buckle run` / `buckle atlas`.
inline const char* const kRunGenerator = "buckle run";
inline const char* const kAtlasGenerator = "buckle atlas";
/// Version of the layout of an output directory (summary.json `schema`).
inline constexpr int kOutputSchema = 1;

/// A refused `--out`: the message names the target and says why (and whether --force helps).
struct OutputTargetError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// True when `dir` is a directory written by buckle: its summary.json carries a `generator`
/// marker (kRunGenerator or kAtlasGenerator; or, written before the marker, the keys of a run's
/// or an atlas's summary) and it holds nothing else than the files buckle writes (top-level
/// CSV/JSON results, plots/ with images, gnuplot scripts, data and logs). Otherwise false, with
/// the reason in `why` when given.
bool isBuckleOutput(const std::string& dir, std::string* why = nullptr);

/// The `generator` of the buckle output in `dir` (as above; "" when there is none).
std::string outputGenerator(const std::string& dir);

/// Applies the policy above to `target` (relative to the current directory); `inputs` are the
/// files the command reads (the scene), which must survive. Returns the absolute path that will
/// be replaced (symbolic links resolved); throws OutputTargetError, naming the option `option`
/// ("--out"), when the target is refused.
std::string checkOutputTarget(const std::string& target, const std::vector<std::string>& inputs, bool force,
                              const std::string& option = "--out");

}  // namespace buckle::scene
