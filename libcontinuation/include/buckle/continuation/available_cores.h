// How many cores this process may run on: what "all cores" means for every pool of worker
// threads (the tree's switches, workspace maps, the atlas).
#pragma once

namespace buckle::continuation {

/// The CPUs in this process's affinity mask (what `taskset` and a container's cpuset leave it),
/// at least 1; where the mask cannot be read, std::thread::hardware_concurrency() (at least 1).
int availableCores();

}  // namespace buckle::continuation
