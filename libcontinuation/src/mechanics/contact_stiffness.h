// The part of the contact stiffness (contact.h) its dense and O(n) routes share. Private to
// libcontinuation/src/mechanics.
#pragma once

#include "buckle/mechanics/stiffness.h"

namespace buckle::mechanics {

/// s's compliance, rotational compliance (rotation free) and stiffness from the products
/// C(i, j) = J_i P J_jᵀ (rows and columns x, y and, with the rotation free, φ; P = Z (ZᵀHZ)⁻¹ Zᵀ),
/// each entry's rounding bound ε·κ·|Zᵀ J_iᵀ|·|P J_jᵀ| (jNorms[i], xNorms[j], κ = condition) below
/// which it is an exact zero; `rigid` where C_F is singular to that bound.
void finishContactStiffness(const Eigen::Ref<const Matrix>& C, const Eigen::Ref<const Vector>& jNorms,
                            const Eigen::Ref<const Vector>& xNorms, double condition, CartesianStiffness& s);

}  // namespace buckle::mechanics
