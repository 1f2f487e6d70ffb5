// The AUTO-07p comparison cases, used by bench_cases, work_precision and hard_cases. Their
// definitions live in apps/problems/auto_cases.h (shared with `buckle regress`); this header
// makes them visible in buckle::bench as before.
#pragma once

#include "../apps/problems/auto_cases.h"
#include "common.h"

namespace buckle::bench {

using namespace buckle::problems;

}  // namespace buckle::bench
