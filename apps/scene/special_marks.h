// How special points are marked and which are labelled, shared by the gnuplot diagrams
// (plot_branches.cpp) and report.html (report.cpp), so that both show the same key, the same
// marker per type and, on a long chain's summary, label the same points.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scene/runner.h"

namespace buckle::scene {

/// The marker of a special-point type.
struct SpecialStyle {
  mechanics::EventType type;
  int point;          ///< gnuplot point type, filled; point - 1 is the open outline
  const char* key;    ///< the key's entry
  const char* color;  ///< the type's colour (summary markers, the report's markers)
  const char* label() const { return mechanics::label(type); }
};

/// Every type in the key's order (BD once: a located boundary and a collapsed joint limit share it).
const std::vector<SpecialStyle>& specialStyles();
/// The style of `type`.
const SpecialStyle& specialStyle(mechanics::EventType type);

/// The field's words for a special point (special_points.json's `field`): its phenomenon
/// ("buckling", "quasi-buckling", "jumping", "none"), or "task path" along a task path.
const char* fieldName(const CaseResult& cr, const mechanics::SpecialPointReport& s);

// A bifurcation diagram of a 50-segment chain carries thousands of special points (2479 in the
// default scene at n = 50: 882 LP, 764 CT, 352 RL, …). Like AUTO's and BifurcationKit's plots of
// large diagrams, the summary labels only the points a reader steers by and draws the others as
// small markers by type, counted in the key.

/// `labels: auto` draws the summary above this many markers (the shipped 3-segment scenes have
/// at most a few dozen, all labelled).
constexpr size_t kSummaryAboveMarkers = 60;
/// Summary labels beyond the branch points of the primary branch (which are all labelled): the
/// jumps, then the first fold of each branch in the order the branches were traced.
constexpr size_t kSummaryExtraLabels = 24;

/// Summary: unlabelled markers of one case and type closer than this many pixels are drawn once.
constexpr double kThinPixels = 4.0;
/// Labels of one case's points closer than this many pixels are merged into one ("BP, JUMP"); a
/// summary merges wider, the branch points of a long chain's primary branch into ranges
/// ("BP 24-27": modes 24 to 27).
constexpr double kMergePixels = 3.0, kSummaryMergePixels = 12.0;

/// A jump's arrow is drawn at least this many pixels long (a hop where the jump is shorter).
constexpr double kJumpMinPixels = 36.0;

/// How much a special point matters in a summary, most first.
enum class Importance { PrimaryBranchPoint, Jump, FirstFold, Other };

/// Per special point of a case (same order as `cr.specials`): the branch points of the primary
/// branches (those with no parent: the start), the jumps (a load history's JUMP, a fold with a
/// simulated jump), the first fold (LP, LPF) of each branch in the order the tracer reported
/// them, the rest.
std::vector<Importance> importance(const CaseResult& cr);

/// The label of a special point: its type, and a branch point's mode or shape ("BP U"; a
/// summary writes "BP 12" for "mode 12", the key says so).
std::string specialLabel(const mechanics::SpecialPointReport& r, bool summary);

/// One label for the texts of points drawn at one place; a summary writes the branch points'
/// modes as ranges ("BP 3, 4", "BP 24-27"), the other texts after them.
std::string mergedLabel(const std::vector<std::string>& parts, bool summary);

}  // namespace buckle::scene
