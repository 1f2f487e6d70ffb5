// A bounded sample of a case's points where the run streams them (RunControl::streamTo): what the
// plots and report.html draw, every stride-th point of each branch with its first and last and the
// points next to a change of stability, the stride doubled whenever the sample outgrows its budget.
#pragma once

#include <cstddef>
#include <vector>

#include "buckle/mechanics/branch_report.h"

namespace buckle::scene {

/// The memory of a sampled point: the report and its vectors.
size_t sampleBytes(const mechanics::PointReport& p);

/// Appends `branch` (one branch's points, in order) to `kept`, sampled at `stride` (a point of
/// index i is kept when i % stride = 0, or it ends its branch, or the stability changes next to
/// it); while the sample's `bytes` exceed `budget` the stride doubles and `kept` is sampled anew.
void keepSample(std::vector<mechanics::PointReport>& kept, std::vector<mechanics::PointReport>&& branch,
                size_t& stride, size_t& bytes, size_t budget);

}  // namespace buckle::scene
