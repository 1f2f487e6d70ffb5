// The dynamics models of dynamics.h: scene data and the common statics (the models' shared
// part and their factory). The gradient flow (D1) is in dynamics_gradient_flow.cpp, the inertial
// model (D2) in dynamics_inertial.cpp, their integration (simulate) in dynamics_integration.cpp.
#include "buckle/mechanics/dynamics.h"

#include "buckle/mechanics/body_loads.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace buckle::mechanics {

namespace {

bool fail(std::string* why, const std::string& message) {
  if (why) *why = message;
  return false;
}

}  // namespace

// ---- scene data ------------------------------------------------------------------------------

InertiaData InertiaData::uniformRods(const Chain& chain, double massPerLength) {
  InertiaData data;
  const Vector& l = chain.linkLengths();
  for (int i = 0; i < chain.size(); ++i) {
    LinkInertia link;
    link.mass = massPerLength * l[i + 1];
    link.inertia = link.mass * l[i + 1] * l[i + 1] / 12.0;
    link.comOffset = 0.5 * l[i + 1];
    data.links.push_back(link);
  }
  return data;
}

InertiaData InertiaData::uniform(const Chain& chain, double mass, double inertia) {
  InertiaData data;
  for (int i = 0; i < chain.size(); ++i) {
    LinkInertia link;
    link.mass = mass;
    link.inertia = inertia;
    data.links.push_back(link);
  }
  return data;
}

bool InertiaData::IsValid(const Chain& chain, std::string* why) const {
  const int n = chain.size();
  if (static_cast<int>(links.size()) != n)
    return fail(why, "inertia: " + std::to_string(links.size()) + " links given, the chain has " +
                         std::to_string(n) + " moving links");
  for (int i = 0; i < n; ++i) {
    const LinkInertia& L = links[size_t(i)];
    const std::string name = "inertia link " + std::to_string(i + 1) + ": ";
    if (!std::isfinite(L.mass) || !(L.mass > 0.0)) return fail(why, name + "mass must be > 0");
    if (!std::isfinite(L.inertia) || L.inertia < 0.0) return fail(why, name + "inertia must be >= 0");
    const double len = chain.linkLengths()[i + 1];
    if (!std::isnan(L.comOffset) && (!std::isfinite(L.comOffset) || L.comOffset < 0.0 || L.comOffset > len))
      return fail(why, name + "comOffset must lie in [0, link length]");
    const double d = std::isnan(L.comOffset) ? 0.5 * len : L.comOffset;
    // Link i's own angular rate is seen by the kinetic energy only through m d² + I: a link with
    // both zero would make M singular.
    if (!(L.mass * d * d + L.inertia > 0.0)) return fail(why, name + "m d² + I must be > 0 (singular mass matrix)");
  }
  return true;
}

bool DynamicsScene::IsValid(const Chain& chain, std::string* why) const {
  if (!std::isfinite(flowDamping) || !(flowDamping > 0.0)) return fail(why, "flowDamping must be > 0");
  if (!jointDamping.empty() && static_cast<int>(jointDamping.size()) != chain.size())
    return fail(why, "jointDamping must be empty or have one entry per joint (" + std::to_string(chain.size()) + ")");
  for (size_t i = 0; i < jointDamping.size(); ++i)
    if (!std::isfinite(jointDamping[i]) || jointDamping[i] < 0.0)
      return fail(why, "jointDamping[" + std::to_string(i) + "] must be >= 0");
  if (!std::isfinite(constraintStiffness)) return fail(why, "constraintStiffness must be finite");
  if (!std::isfinite(baumgarteRate)) return fail(why, "baumgarteRate must be finite");
  if (inertia && !inertia->IsValid(chain, why)) return false;
  if (body) {
    try {
      body->check(chain);
    } catch (const std::invalid_argument& e) {
      return fail(why, e.what());
    }
  }
  return true;
}

// ---- common part -----------------------------------------------------------------------------

DynamicsModel::DynamicsModel(const Chain& chain, const EndCondition& end)
    : chain_(chain),
      end_(end),
      lengthUnit_(0.0),
      torqueUnit_(0.0),
      held_(end.heldIndices()),
      loaded_(end.loadedIndices()),
      sides_(size_t(chain.size()), 0),
      loads_(Wrench::Zero()),
      data_(chain),
      J_(3, chain.size()),
      grad_(chain.size()),
      stiffness_(chain.size()),
      staticsQ_(chain.size()),
      sinHalf_(chain.size()),
      cosHalf_(chain.size()),
      Jh_(end.heldCount(), chain.size()),
      h_(end.heldCount()),
      A_(end.heldCount(), end.heldCount()),
      llt_(end.heldCount()),
      r_(end.heldCount()),
      tmpM_(end.heldCount()),
      tmpN_(chain.size()) {
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(end.value[c])) throw std::invalid_argument("end condition value " + std::to_string(c) + " must be finite");
  for (int c : loaded_) loads_[c] = end.value[c];
  llt_.compute(Matrix::Identity(heldCount(), heldCount()));  // defines its status flag
  double b = 0.0, k = 0.0;
  for (int i = 0; i < chain.size(); ++i) {
    b += 0.5 * (chain.segment(i).parameters().b1 + chain.segment(i).parameters().b2);
    k += 0.5 * (chain.segment(i).parameters().k1 + chain.segment(i).parameters().k2);
  }
  lengthUnit_ = b / chain.size();
  torqueUnit_ = k / chain.size() * lengthUnit_ * lengthUnit_;
}

void DynamicsModel::evaluateStatics(ConstVectorRef q) {
  const int n = segments();
  if (staticsValid_ && std::equal(q.data(), q.data() + n, staticsQ_.data())) return;
  staticsValid_ = false;
  // E, ∂E/∂q, K_q and the kinematics from one sincos per joint: the springs' half angles also
  // give the link directions (forwardKinematics from half angles, chain.h).
  springEnergy_ = 0.0;
  for (int i = 0; i < n; ++i) {
    const double sh = std::sin(0.5 * q[i]), ch = std::cos(0.5 * q[i]);  // one sincos call at -O2
    sinHalf_[i] = sh;
    cosHalf_[i] = ch;
    const Jet3 e = chain_.segment(i).energyJet(q[i], sh, ch);
    springEnergy_ += e.value;
    grad_[i] = e.d1;
    stiffness_[i] = e.d2;
  }
  forwardKinematics(chain_, q, sinHalf_.data(), cosHalf_.data(), data_);
  endJacobian(data_, J_);
  // ∇Π = ∂E/∂q − J_lᵀ F_l (eq 9, loads_ zero on held coordinates; J rows (−S, C, 1))
  for (int i = 0; i < n; ++i) grad_[i] = grad_[i] + loads_[0] * data_.S[i] - loads_[1] * data_.C[i] - loads_[2];
  bodyPotential_ = 0.0;
  if (body_) {  // ∂V/∂q = −τ (eq B2), O(n)
    body_->update(data_);
    body_->torques(0.0, bodyWork_);
    grad_ -= bodyWork_;
    bodyPotential_ = body_->potential(data_, 0.0);
  }
  staticsQ_ = q;
  staticsValid_ = true;
  const int mh = heldCount(), m = constraintCount();
  if (m == 0) return;
  for (int k = 0; k < mh; ++k) {
    const int c = held_[size_t(k)];
    Jh_.row(k) = J_.row(c);
    h_[k] = data_.pose[c] - end_.value[c];
  }
  // locked joints: rows e_iᵀ, h = q_i − q̄_i (Jh_ holds their zeros since setContacts)
  const int w0 = wallRowBegin();
  for (int k = mh; k < w0; ++k) {
    const int i = locked_[size_t(k - mh)];
    h_[k] = q[i] - limitAngle(i, sides_[size_t(i)]);
  }
  if (!wall_.empty() || !self_.empty()) gapRows();
  A_.noalias() = Jh_ * Jh_.transpose();
  // J_h loses rank where the held coordinate is stationary (x held on the straight chain): a
  // relative 1e-12 shift keeps the factorization defined and is invisible at regular points.
  // (Not on the locked rows, unit rows, nor on the wall rows, whose vertices a wall force keeps
  // off their joints' line: the shift would let the joint or the vertex creep by ε r / κ_h.)
  if (mh > 0)
    A_.diagonal().head(mh).array() += 1e-12 * std::max(lengthUnit_ * lengthUnit_, A_.topLeftCorner(mh, mh).trace());
  llt_.compute(A_);
}

void DynamicsModel::gapRows() {
  // Joint j at end − (C_j, S_j) (the tail sums of ChainData: ∂y/∂q_j = x_end − x_Pj, −∂x/∂q_j =
  // y_end − y_Pj), as jointPositions' column j + 1, without a sine or cosine.
  const int n = segments();
  positions_.col(0).setZero();
  for (int j = 0; j < n; ++j) positions_.col(j + 1) << data_.pose[0] - data_.C[j], data_.pose[1] - data_.S[j];
  positions_.col(n + 1) << data_.pose[0], data_.pose[1];
  const int w0 = wallRowBegin();
  for (int k = 0; k < wallCount(); ++k) {
    const WallVertex& v = wall_[size_t(k)];
    const double before = v.segment > 0 ? data_.theta[v.segment - 1] : 0.0;
    const Eigen::Vector2d point =
        segmentVertex(chain_.segment(v.segment).parameters(), positions_.col(v.segment + 1), before, data_.theta[v.segment],
                      v.corner);
    wallVertexDerivatives(positions_, point, v, wallRow_, wallGen_.col(k));
    Jh_.row(w0 + k) = wallRow_.transpose();
    h_[w0 + k] = point.x();
  }
  const int s0 = selfRowBegin();
  for (int k = 0; k < selfCount(); ++k) {
    const SelfContact& c = self_[size_t(k)];
    const SelfContactGap g = selfContactGap(chain_, staticsQ_, positions_, c);
    selfContactDerivatives(positions_, c, g, wallRow_, wallGen_.col(wallCount() + k), selfCoupling_.col(k),
                           selfWeights_.col(k));
    Jh_.row(s0 + k) = wallRow_.transpose();
    h_[s0 + k] = g.gap;
  }
}

double DynamicsModel::potential(ConstVectorRef q) {
  evaluateStatics(q);
  return springEnergy_ - loads_.dot(data_.pose) + bodyPotential_;
}

void DynamicsModel::setBodyLoads(const BodyLoads& body) {
  body.check(chain_);
  if (!body.active()) {
    body_.reset();
    return;
  }
  body_ = std::make_shared<BodyLoadTerms>(chain_, body.atParameter(0.0));
  bodyWork_.resize(chain_.size());
  staticsValid_ = false;
}

void DynamicsModel::subtractBodyGenerator(VectorRef h) {
  if (!body_) return;
  body_->generator(0.0, bodyWork_);
  h -= bodyWork_;
}

void DynamicsModel::addBodyHessian(MatrixRef H) {
  if (!body_) return;
  body_->generator(0.0, bodyWork_);
  addBodyLoadHessian(bodyWork_, H);
}

void DynamicsModel::potentialGradient(ConstVectorRef q, VectorRef g) {
  evaluateStatics(q);
  g = grad_;
}

double DynamicsModel::equilibriumResidual(ConstVectorRef q) {
  evaluateStatics(q);
  if (constraintCount() == 0) return grad_.cwiseAbs().maxCoeff();
  // P∇Π = ∇Π − J_hᵀ r with the least-squares reactions r = (J_h J_hᵀ)⁻¹ J_h ∇Π.
  tmpM_.noalias() = Jh_ * grad_;
  llt_.solveInPlace(tmpM_);
  tmpN_ = grad_;
  tmpN_.noalias() -= Jh_.transpose() * tmpM_;
  return std::max(tmpN_.cwiseAbs().maxCoeff(), h_.cwiseAbs().maxCoeff());
}

double DynamicsModel::naturalResidual(ConstVectorRef q) {
  const double raw = equilibriumResidual(q);  // fills grad_ / tmpN_ and h_
  if (constraintCount() == 0) return raw / torqueUnit_;
  const int mh = heldCount();
  // held and wall rows in lengths, locked rows in radians (their own unit)
  double h = mh > 0 ? h_.head(mh).cwiseAbs().maxCoeff() / lengthUnit_ : 0.0;
  if (lockedCount() > 0) h = std::max(h, h_.segment(mh, lockedCount()).cwiseAbs().maxCoeff());
  const int gaps = wallCount() + selfCount();  // the wall's and the self contacts' gaps, lengths
  if (gaps > 0) h = std::max(h, h_.tail(gaps).cwiseAbs().maxCoeff() / lengthUnit_);
  return std::max(tmpN_.cwiseAbs().maxCoeff() / torqueUnit_, h);
}

double DynamicsModel::constraintViolation(ConstVectorRef q) {
  if (heldCount() == 0) return 0.0;
  evaluateStatics(q);
  double v = 0.0;
  for (int c : held_) v = std::max(v, std::abs(data_.pose[c] - end_.value[c]));
  return v;
}

bool DynamicsModel::projectOntoConstraints(VectorRef q, double tolerance, int maxIterations) {
  if (constraintCount() == 0) return true;
  for (int it = 0; it <= maxIterations; ++it) {
    evaluateStatics(q);
    if (h_.cwiseAbs().maxCoeff() <= tolerance * std::max(1.0, lengthUnit_)) return true;
    if (it == maxIterations) break;
    // Minimum-norm Gauss–Newton correction δq = −J_hᵀ (J_h J_hᵀ)⁻¹ h.
    tmpM_ = h_;
    llt_.solveInPlace(tmpM_);
    q.noalias() -= Jh_.transpose() * tmpM_;
  }
  return false;
}

bool DynamicsModel::withinLimits(ConstVectorRef q) const {
  for (int i = 0; i < segments(); ++i)
    if (sides_[size_t(i)] == 0 && !(q[i] > chain_.lowerLimits()[i] && q[i] < chain_.upperLimits()[i])) return false;
  return true;
}

double DynamicsModel::limitAngle(int joint, int side) const {
  return side > 0 ? chain_.upperLimits()[joint] : chain_.lowerLimits()[joint];
}

void DynamicsModel::setContacts(const std::vector<int>& sides) {
  const int n = segments();
  if (static_cast<int>(sides.size()) != n)
    throw std::invalid_argument("contact sides: " + std::to_string(sides.size()) + " entries for " + std::to_string(n) + " joints");
  for (int s : sides)
    if (s < -1 || s > 1) throw std::invalid_argument("contact sides must be -1, 0 or +1");
  sides_ = sides;
  locked_.clear();
  for (int i = 0; i < n; ++i)
    if (sides_[size_t(i)] != 0) locked_.push_back(i);
  rebuildConstraints();
}

namespace {

// Each contact checked (`check` throws for one that is not the chain's) and given once.
template <class Contact, class Check>
void checkContacts(const std::vector<Contact>& contacts, Check check, const char* what) {
  for (size_t k = 0; k < contacts.size(); ++k) {
    check(contacts[k]);
    if (std::find(contacts.begin(), contacts.begin() + long(k), contacts[k]) != contacts.begin() + long(k))
      throw std::invalid_argument(std::string(what) + contacts[k].label() + " given twice");
  }
}

}  // namespace

void DynamicsModel::setWallContacts(const std::vector<WallVertex>& vertices) {
  checkContacts(vertices, [this](const WallVertex& v) { checkWallVertex(v, segments()); }, "wall contacts: vertex ");
  wall_ = vertices;
  rebuildConstraints();
}

void DynamicsModel::setSelfContacts(const std::vector<SelfContact>& contacts) {
  checkContacts(contacts, [this](const SelfContact& c) { checkSelfContact(c, segments()); }, "self contacts: ");
  self_ = contacts;
  rebuildConstraints();
}

void DynamicsModel::rebuildConstraints() {
  const int n = segments();
  staticsValid_ = false;  // h_ and the rows depend on the contact set
  const int mh = heldCount(), m = constraintCount();
  Matrix held = Jh_.topRows(mh);
  Jh_ = Matrix::Zero(m, n);
  Jh_.topRows(mh) = held;
  for (int k = mh; k < wallRowBegin(); ++k) Jh_(k, locked_[size_t(k - mh)]) = 1.0;
  wallGen_ = Matrix::Zero(n, wallCount() + selfCount());
  selfCoupling_ = Matrix::Zero(n, selfCount());
  selfWeights_ = Matrix::Zero(n, selfCount());
  positions_.resize(2, n + 2);
  wallRow_.resize(n);
  h_ = Vector::Zero(m);
  A_ = Matrix::Identity(m, m);
  llt_.compute(A_);
  r_ = Vector::Zero(m);
  tmpM_ = Vector::Zero(m);
  resizeConstraints();
}

void DynamicsModel::contactTorques(const double* x, VectorRef torques) {
  wallForces_.resize(wallCount());
  selfForces_.resize(selfCount());
  contactForces(x, torques, wallForces_, selfForces_);
}

void DynamicsModel::contactForces(const double* x, VectorRef torques, VectorRef wallForces) {
  selfForces_.resize(selfCount());
  contactForces(x, torques, wallForces, selfForces_);
}

void DynamicsModel::contactForces(const double* x, VectorRef torques, VectorRef wallForces, VectorRef selfForces) {
  torques.setZero();
  if (locked_.empty() && wall_.empty() && self_.empty()) return;
  fdPlus_.resize(size_t(stateSize()));
  rhs(x, fdPlus_.data());  // the multipliers r_ at x
  for (int k = 0; k < lockedCount(); ++k) torques[locked_[size_t(k)]] = r_[heldCount() + k];
  wallForces = r_.segment(wallRowBegin(), wallCount());
  selfForces = r_.tail(selfCount());
}

double DynamicsModel::restSpeed(const double* x) {
  tmpN_.resize(segments());
  velocity(x, tmpN_);
  return tmpN_.cwiseAbs().maxCoeff();
}

double DynamicsModel::impact(double* x) {
  for (int i : locked_) x[i] = limitAngle(i, sides_[size_t(i)]);
  return 0.0;
}

void DynamicsModel::jacobian(const double* x, double* jacobianRowMajor) {
  // Central differences of the analytic right-hand side, step ~ ε^{1/3} scaled to the entry:
  // the stiff stepper only needs its W = I − γhJ to be a good preconditioner-quality matrix;
  // the accuracy of the solution is set by the error control on rhs().
  const int N = stateSize();
  fdState_.assign(x, x + N);
  fdPlus_.resize(size_t(N));
  fdMinus_.resize(size_t(N));
  for (int j = 0; j < N; ++j) {
    const double h = 6e-6 * std::max(1.0, std::abs(x[j]));
    fdState_[size_t(j)] = x[j] + h;
    rhs(fdState_.data(), fdPlus_.data());
    fdState_[size_t(j)] = x[j] - h;
    rhs(fdState_.data(), fdMinus_.data());
    fdState_[size_t(j)] = x[j];
    for (int i = 0; i < N; ++i) jacobianRowMajor[i * N + j] = (fdPlus_[size_t(i)] - fdMinus_[size_t(i)]) / (2.0 * h);
  }
}

bool DynamicsModel::solveLinearized(const double*, double, const double*, double*) { return false; }

std::unique_ptr<DynamicsModel> makeDynamicsModel(const Chain& chain, const EndCondition& end,
                                                 const DynamicsScene& scene, ConstVectorRef q0) {
  std::string why;
  if (!scene.IsValid(chain, &why)) throw std::invalid_argument(why);
  std::unique_ptr<DynamicsModel> model;
  if (scene.inertia)
    model = std::make_unique<InertialModel>(chain, end, *scene.inertia, scene.jointDamping, scene.baumgarteRate, q0);
  else
    model = std::make_unique<GradientFlowModel>(chain, end, scene, q0);
  if (scene.body) model->setBodyLoads(*scene.body);
  return model;
}

}  // namespace buckle::mechanics
