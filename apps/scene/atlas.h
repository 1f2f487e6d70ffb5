// A two-parameter atlas of the clamped–pinned chain (y held at 0, end rotation free, Fx
// compression): over a grid of two of (a/b, L0/b, n) — b = k = 1, equal preloads, straight
// start — the stability of the straight configuration, the first critical force and the
// character of the post-buckling branch, computed on all cores.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "buckle/continuation/interrupt.h"

namespace buckle::scene {

/// An axis of the atlas: "a" (a/b), "L0" (L0/b) or "n" (segment count), `count` values from
/// `from` to `to` inclusive.
struct AtlasAxis {
  std::string name;
  double from = 0.0, to = 1.0;
  int count = 11;
  double value(int i) const { return count == 1 ? from : from + (to - from) * i / (count - 1); }
};

struct AtlasOptions {
  AtlasAxis x{"a", 0.05, 1.0, 20}, y{"L0", 1.0, 3.0, 21};
  /// Values of the parameters that are not an axis.
  double a = 0.5, L0 = 2.25;
  int n = 3;
  int threads = 0;  ///< 0: std::thread::hardware_concurrency()
};

struct AtlasCell {
  double x = 0.0, y = 0.0;
  double a = 0.0, L0 = 0.0;
  int n = 0;
  double kappa = 0.0;               ///< straight joint stiffness k(b L0 − 2(b² − a²))
  bool straightStable = false;
  double firstCritical = 0.0;       ///< first compressive critical Fx (NaN: none)
  std::string firstShape;           ///< shape of its mode
  /// "supercritical" (the bifurcating branch is stable under force control), "subcritical"
  /// (unstable), "unstable start" (κ <= 0), "none" (no compressive critical load),
  /// "failed" (the branch could not be followed), "not computed" (the run was stopped first).
  std::string postBuckling;
  double postSlope = 0.0;           ///< d|Fx| along the new branch over the first steps (> 0: rising)
  std::string error;
};

/// Validates the axes; throws std::invalid_argument naming the option.
void validateAtlas(const AtlasOptions& options);

/// The cells of the grid (row-major: y outer, x inner) with their parameters and κ set, not yet
/// computed (postBuckling "not computed", firstCritical NaN).
std::vector<AtlasCell> atlasGrid(const AtlasOptions& options);

/// The part of the grid one process computes when several share it: the cells k with
/// k mod parts = part. Interleaved rather than in blocks because the cost of a cell grows
/// along an axis (n, or towards κ = 0), so every part gets a similar mix.
struct AtlasShare {
  int part = 0, parts = 1;
  bool owns(size_t k) const { return k % size_t(parts) == size_t(part); }
  size_t size(size_t cells) const { return cells / size_t(parts) + (size_t(part) < cells % size_t(parts) ? 1 : 0); }
};

/// Computes the cells of `share` on `threads` worker threads (0: all cores). Once `interrupt`
/// is requested no new cell is started: those left keep "not computed", with the reason in
/// `error`. `progress(done, total)` (total: the share's cells) is called from the workers,
/// serialised, after each cell. Returns the number of cells computed.
size_t computeCells(std::vector<AtlasCell>& cells, const AtlasShare& share, int threads,
                    const continuation::Interrupt& interrupt,
                    const std::function<void(int, int)>& progress = nullptr);

/// Every cell of the grid on options.threads threads, never interrupted.
std::vector<AtlasCell> computeAtlas(const AtlasOptions& options,
                                    const std::function<void(int, int)>& progress = nullptr);

/// The computed fields of the share's cells as bytes (doubles bit for bit), to be sent to the
/// process that writes the atlas, and back into the same grid there. unpackAtlasCells throws
/// std::runtime_error on bytes that do not fit the grid.
std::string packAtlasCells(const std::vector<AtlasCell>& cells, const AtlasShare& share);
void unpackAtlasCells(const std::string& bytes, std::vector<AtlasCell>& cells);

/// atlas.csv and the heat maps into an existing directory; returns the image files written
/// (empty when gnuplot is missing) and sets `gnuplotNote`.
std::vector<std::string> writeAtlas(const AtlasOptions& options, const std::vector<AtlasCell>& cells,
                                    const std::string& dir, std::string& gnuplotNote);

}  // namespace buckle::scene
