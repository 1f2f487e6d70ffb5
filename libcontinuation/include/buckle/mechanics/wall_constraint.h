// The base wall's and the self contacts' terms in the linearisation about an equilibrium with
// vertices held on the wall or on other links (contact.h, wall_contact.h, self_contact.h): shared
// by the loaded stiffness and the vibration modes of such a point, which see the same constrained
// chain.
#pragma once

#include "buckle/mechanics/contact.h"

namespace buckle::mechanics {

/// The vertices of `contacts` on the wall at q: their rows ∇x_vᵀ into `rows` (w × n, row k the
/// k-th vertex), and their forces' −Σ μ_v ∂²x_v added to the body-load generator as
/// γ += μ_v g_v (wall_contact.h; `generator` zeros of size n first when it is empty and a vertex
/// is on the wall, untouched when none is). Throws
/// std::invalid_argument, naming `caller`, unless there is one force per vertex on the wall.
void wallConstraintTerms(const Chain& chain, ConstVectorRef q, const ContactSet& contacts, ConstVectorRef wallForces,
                         const char* caller, MatrixRef rows, Vector& generator);

/// The same for the self contacts of `contacts` (self_contact.h), forces in contacts.self()'s
/// order: their rows ∇gᵀ into `rows` (s × n), and −Σ μ ∂²g as its generator part (γ += μ γ_g,
/// `generator` as above) and its rank-2 part −Σ μ (c wᵀ + w cᵀ) as R E Rᵀ (selfCouplingColumns):
/// R into `columns` (n × 2s), E's diagonal into `signs`. Throws std::invalid_argument, naming
/// `caller`, unless there is one force per self contact.
void selfConstraintTerms(const Chain& chain, ConstVectorRef q, const ContactSet& contacts, ConstVectorRef selfForces,
                         const char* caller, MatrixRef rows, Vector& generator, Matrix& columns, Vector& signs);

}  // namespace buckle::mechanics
