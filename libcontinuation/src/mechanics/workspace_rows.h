// The rows of a workspace map (workspace_map.h) as the rest of its computation needs them, and as
// bytes: what one process sends the others when several share a map (WorkspaceShare).
#pragma once

#include <string>
#include <vector>

#include "workspace_curves.h"

namespace buckle::mechanics::detail {

/// What a traced row leaves besides its cells (which are in the map): the curves it starts (its
/// located folds and joint stops, in tracing order), the box's edge when it is the first or the
/// last row, and why it could not be traced.
struct WorkspaceRow {
  bool done = false;         ///< traced here or received (false: still to trace)
  std::vector<CurveStart> starts;
  bool hasEdge = false;
  WorkspaceCurve edge;
  std::string problem;       ///< empty: none
};

/// The rows `which` (their cells in `map` and their WorkspaceRow) as bytes, doubles bit for bit.
std::string packWorkspaceRows(const WorkspaceMap& map, const std::vector<WorkspaceRow>& rows,
                              const std::vector<int>& which);
/// The rows in `bytes` back into the same grid, each marked done. Throws std::runtime_error on
/// bytes that do not fit the grid.
void unpackWorkspaceRows(const std::string& bytes, WorkspaceMap& map, std::vector<WorkspaceRow>& rows);

}  // namespace buckle::mechanics::detail
