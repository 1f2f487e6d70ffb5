#include "buckle/mechanics/control_path.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <vector>

namespace buckle::mechanics {

namespace {
// d(L1⁰, L2⁰)/d(input): the input's definition inverted with the other mode kept.
Eigen::RowVector2d ratesOf(ControlInput input) {
  switch (input) {
    case ControlInput::L1_0: return {1.0, 0.0};
    case ControlInput::L2_0: return {0.0, 1.0};
    case ControlInput::L0: return {1.0, 1.0};
    case ControlInput::dL0: return {0.5, -0.5};
  }
  return {0.0, 0.0};
}
}  // namespace

ControlDirection ControlDirection::named(int n, ControlInput input, int segment) {
  if (n < 1) throw std::invalid_argument("control direction: the chain needs at least one segment");
  if (segment < -1 || segment >= n)
    throw std::invalid_argument("control direction: segment " + std::to_string(segment + 1) + " out of range 1.." +
                                std::to_string(n));
  ControlDirection d;
  d.rates = Eigen::MatrixX2d::Zero(n, 2);
  for (int i = 0; i < n; ++i)
    if (segment < 0 || segment == i) d.rates.row(i) = ratesOf(input);
  return d;
}

ControlInput complementaryInput(ControlInput input) {
  switch (input) {
    case ControlInput::L1_0: return ControlInput::L2_0;
    case ControlInput::L2_0: return ControlInput::L1_0;
    case ControlInput::L0: return ControlInput::dL0;
    case ControlInput::dL0: return ControlInput::L0;
  }
  return ControlInput::L0;
}

void addComplementaryRates(ControlDirection& d, ControlInput input, const Eigen::VectorXd& rates) {
  const int n = int(d.rates.rows());
  if (rates.size() != 1 && rates.size() != n)
    throw std::invalid_argument("control direction: expected one rate of " + controlInputName(complementaryInput(input)) +
                                " or one per segment (" + std::to_string(n) + "), got " + std::to_string(rates.size()));
  if (!rates.allFinite()) throw std::invalid_argument("control direction: the rates must be finite");
  const ControlDirection unit = ControlDirection::named(n, complementaryInput(input));
  for (int i = 0; i < n; ++i) d.rates.row(i) += rates[rates.size() == 1 ? 0 : i] * unit.rates.row(i);
}

std::string controlInputName(ControlInput input) {
  switch (input) {
    case ControlInput::L1_0: return "L1_0";
    case ControlInput::L2_0: return "L2_0";
    case ControlInput::L0: return "L0";
    case ControlInput::dL0: return "dL0";
  }
  return "";
}

bool parseControlInput(const std::string& name, ControlInput& input) {
  for (ControlInput c : {ControlInput::L1_0, ControlInput::L2_0, ControlInput::L0, ControlInput::dL0})
    if (name == controlInputName(c)) {
      input = c;
      return true;
    }
  return false;
}

double controlInputValue(const Chain& chain, ControlInput input, int segment) {
  const auto value = [input](const SegmentParameters& p) {
    switch (input) {
      case ControlInput::L1_0: return p.L1_0;
      case ControlInput::L2_0: return p.L2_0;
      case ControlInput::L0: return 0.5 * (p.L1_0 + p.L2_0);
      case ControlInput::dL0: return p.L1_0 - p.L2_0;
    }
    return 0.0;
  };
  if (segment >= 0) return value(chain.segment(segment).parameters());
  double sum = 0.0;
  for (int i = 0; i < chain.size(); ++i) sum += value(chain.segment(i).parameters());
  return sum / chain.size();
}

Chain chainWithControls(const Chain& chain, const ControlDirection& control, double lambda) {
  std::vector<SegmentParameters> p(size_t(chain.size()));
  const double t = lambda - control.origin;
  for (int i = 0; i < chain.size(); ++i) {
    p[size_t(i)] = chain.segment(i).parameters();
    if (!control.active()) continue;
    p[size_t(i)].L1_0 += t * control.rates(i, 0);
    p[size_t(i)].L2_0 += t * control.rates(i, 1);
  }
  return Chain(p);  // validates: "segment i: L1_0 must be > 0 …"
}

std::pair<double, double> admissibleRange(const Chain& chain, const ControlDirection& d) {
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  for (int i = 0; i < chain.size(); ++i) {
    const SegmentParameters& sp = chain.segment(i).parameters();
    const double L[2] = {sp.L1_0, sp.L2_0};
    for (int s = 0; s < 2; ++s) {
      const double r = d.rates(i, s);
      if (r > 0.0) lo = std::max(lo, d.origin - L[s] / r);
      if (r < 0.0) hi = std::min(hi, d.origin - L[s] / r);
    }
  }
  return {lo, hi};
}

}  // namespace buckle::mechanics
