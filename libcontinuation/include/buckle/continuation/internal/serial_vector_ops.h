// Lean replacements for the serial N_Vector operations KINSOL calls per Newton iteration.
//
// For the corrector's tiny vectors (N+1 = 4…8 entries) the library's serial operations cost
// ≈ 30–100 instructions per call (the weighted 2-norm ≈ 100, benchmarks/RESULTS.md section 2), and a
// KINSol call makes ≈ 10 of them. The replacements below do exactly the same floating-point
// operations in the same order as N_V*_Serial of SUNDIALS 6.4 (a sequential sum of squares of
// x_i·w_i, then sqrt; element-wise products; the first-largest |x_i|; the smallest x_i; c·x_i,
// which equals the library's copy and negation branches for c = ±1 exactly), so every KINSOL
// iterate stays bit for bit the same. Installed in a vector's operation table, they are inherited
// by every N_VClone of it (KINSOL's work vectors are clones of the vector given to KINInit).
#pragma once

#include <nvector/nvector_serial.h>

namespace buckle::continuation {

/// Replaces N_VWL2Norm, N_VProd, N_VMaxNorm, N_VMin, N_VScale, N_VConst and N_VLinearSum (its
/// a = b = 1 case; the others stay the library's) of the serial vector
/// v (and of its future clones) by the lean versions. v must be an NVECTOR_SERIAL.
void useLeanSerialOperations(N_Vector v);

}  // namespace buckle::continuation
