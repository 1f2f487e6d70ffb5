#include "scene/special_marks.h"

#include <algorithm>
#include <stdexcept>

namespace buckle::scene {

namespace mech = buckle::mechanics;
using mech::EventType;

const std::vector<SpecialStyle>& specialStyles() {
  static const std::vector<SpecialStyle> styles = {
      {EventType::BranchPoint, 7, "BP branch point", "#000000"},
      {EventType::Fold, 9, "LP fold", "#d62728"},
      {EventType::ReactionFold, 9, "LPF reaction fold", "#ff7f0e"},
      {EventType::Boundary, 5, "BD joint limit", "#8c564b"},
      {EventType::StabilityLoss, 9, "LS loss of stability at fixed inputs", "#e377c2"},
      {EventType::InputBound, 5, "IB input bound", "#bcbd22"},
      {EventType::StiffnessMinimum, 13, "KMIN Kxx minimum", "#9467bd"},
      {EventType::Jump, 11, "JUMP release", "#ff7f0e"},
      {EventType::Contact, 15, "CT contact (joint locks)", "#2ca02c"},
      {EventType::Release, 3, "RL contact released", "#17becf"},
      {EventType::WallContact, 15, "WC vertex on the wall", "#006d2c"},
      {EventType::WallRelease, 3, "WR vertex leaves the wall", "#08519c"},
      {EventType::SelfHold, 15, "SH vertex held on another link", "#54278f"},
      {EventType::SelfRelease, 3, "SR self contact released", "#807dba"},
      {EventType::BaseContact, 5, "BC base contact (detected)", "#e377c2"},
      {EventType::SelfContact, 5, "SC self contact (detected)", "#7f7f7f"},
      {EventType::EigenvalueTouch, 7, "ET eigenvalue touches zero", "#555555"}};
  return styles;
}

const SpecialStyle& specialStyle(EventType type) {
  if (type == EventType::JointLimit) type = EventType::Boundary;
  for (const SpecialStyle& s : specialStyles())
    if (type == s.type) return s;
  throw std::logic_error(std::string("no marker style for special points ") + mech::label(type));
}

const char* fieldName(const CaseResult& cr, const mech::SpecialPointReport& s) {
  return cr.inputNames.empty() ? mech::toString(s.phenomenon) : "task path";
}

std::vector<Importance> importance(const CaseResult& cr) {
  std::vector<int> primary;
  for (const BranchRecord& b : cr.branches)
    if (b.parent < 0) primary.push_back(b.id);
  std::vector<int> folded;
  std::vector<Importance> out;
  for (const SpecialPointResult& r : cr.specials) {
    Importance k = Importance::Other;
    if (r.type == EventType::BranchPoint && std::find(primary.begin(), primary.end(), r.branch) != primary.end())
      k = Importance::PrimaryBranchPoint;
    else if (r.type == EventType::Jump || r.landing.success)
      k = Importance::Jump;
    else if ((r.type == EventType::Fold || r.type == EventType::ReactionFold) &&
             std::find(folded.begin(), folded.end(), r.branch) == folded.end()) {
      folded.push_back(r.branch);
      k = Importance::FirstFold;
    }
    out.push_back(k);
  }
  return out;
}

std::string specialLabel(const mech::SpecialPointReport& r, bool summary) {
  std::string label = mech::label(r.type);
  if (r.type == EventType::BranchPoint && !r.shape.empty() && r.shape != "other")
    label += " " + (summary && r.shape.rfind("mode ", 0) == 0 ? r.shape.substr(5) : r.shape);
  return label;
}

std::string mergedLabel(const std::vector<std::string>& parts, bool summary) {
  std::vector<int> modes;
  std::vector<std::string> rest;
  for (const std::string& p : parts) {
    const bool mode = summary && p.size() > 3 && p.rfind("BP ", 0) == 0 &&
                      p.find_first_not_of("0123456789", 3) == std::string::npos;
    if (mode)
      modes.push_back(std::stoi(p.substr(3)));
    else
      rest.push_back(p);
  }
  std::string text;
  std::sort(modes.begin(), modes.end());
  for (size_t i = 0; i < modes.size();) {
    size_t j = i;
    while (j + 1 < modes.size() && modes[j + 1] == modes[j] + 1) ++j;
    text += (i ? ", " : "BP ") + std::to_string(modes[i]);
    if (j == i + 1) text += ", " + std::to_string(modes[j]);
    if (j > i + 1) text += "-" + std::to_string(modes[j]);
    i = j + 1;
  }
  for (const std::string& p : rest) text += (text.empty() ? "" : ", ") + p;
  return text;
}

}  // namespace buckle::scene
