#include "scene/units.h"

#include <array>
#include <string_view>

namespace buckle::scene {

namespace {

constexpr size_t kMaxUnitBytes = 16;

// The multi-byte characters a unit name may hold besides printable ASCII: µ (micro sign),
// μ (Greek mu), · (middle dot), ² and ³.
constexpr std::array<std::string_view, 5> kUnicodeAllowed = {"\xC2\xB5", "\xCE\xBC", "\xC2\xB7", "\xC2\xB2", "\xC2\xB3"};

bool safeUnitName(const std::string& s) {
  if (s.empty() || s.size() > kMaxUnitBytes || s.front() == ' ' || s.back() == ' ') return false;
  for (size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == ' ' || c == '.' ||
        c == '/' || c == '^' || c == '*' || c == '-') {
      ++i;
      continue;
    }
    bool matched = false;
    for (std::string_view u : kUnicodeAllowed)
      if (std::string_view(s).substr(i, u.size()) == u) {
        i += u.size();
        matched = true;
        break;
      }
    if (!matched) return false;
  }
  return true;
}

// "N/m" from force "N" and length "m"; a compound name in parentheses ("kg m/s^2" → "(kg m/s^2)/m").
std::string group(const std::string& unit) {
  return unit.find_first_of(" /*·") == std::string::npos ? unit : "(" + unit + ")";
}

}  // namespace

bool validUnitName(const std::string& name) { return safeUnitName(name); }

std::string UnitSystem::unit(Dimension d) const {
  switch (d) {
    case Dimension::None: return "";
    case Dimension::Angle: return "rad";
    case Dimension::Time: return kind == Kind::Nondimensional ? "model time units" : "model time";
    case Dimension::Frequency: return "1/model time";
    case Dimension::AngularFrequency:
      // ω² = (joint stiffness F·L) / (mass·L²): rad per √(mass·L/F)
      if (kind == Kind::Nondimensional) return "√(k/m)";  // b = k = 1, masses in a unit m
      if (kind == Kind::Consistent) return "rad/time";
      if (mass.empty()) return "rad/time";
      if (length == "m" && force == "N" && mass == "kg") return "rad/s";
      return "rad/(" + mass + "·" + length + "/" + force + ")^1/2";
    case Dimension::Acceleration:
      // the weight m g is a force: g in force per mass unit
      if (kind == Kind::Nondimensional) return "k b/m";  // masses in a unit m
      if (kind == Kind::Consistent || mass.empty()) return "force/mass";
      if (length == "m" && force == "N" && mass == "kg") return "m/s^2";
      return group(force) + "/" + group(mass);
    default: break;
  }
  if (kind == Kind::Nondimensional) {
    switch (d) {
      case Dimension::Length: return "b";
      case Dimension::Force: return "k b";
      case Dimension::Moment: return "k b^2";
      case Dimension::Stiffness: return "k";
      case Dimension::Compliance: return "1/k";
      case Dimension::RotationalStiffness: return "k b^2/rad";
      default: return "";
    }
  }
  const std::string L = kind == Kind::Named ? length : "length", F = kind == Kind::Named ? force : "force";
  switch (d) {
    case Dimension::Length: return L;
    case Dimension::Force: return F;
    case Dimension::Moment: return group(F) + "·" + group(L);
    case Dimension::Stiffness: return group(F) + "/" + group(L);
    case Dimension::Compliance: return group(L) + "/" + group(F);
    case Dimension::RotationalStiffness: return group(F) + "·" + group(L) + "/rad";
    default: return "";
  }
}

std::string UnitSystem::suffix(Dimension d) const {
  if (d == Dimension::None) return "";
  if (d == Dimension::Angle || kind == Kind::Named) return " (" + unit(d) + ")";
  if (d == Dimension::AngularFrequency && kind == Kind::Nondimensional) return " (units of √(k/m), m the mass unit)";
  if (kind == Kind::Nondimensional) return " (units of " + unit(d) + ")";
  return " (" + unit(d) + ", in the scene's units)";
}

nlohmann::json UnitSystem::toJson() const {
  nlohmann::json j;
  j["system"] = kind == Kind::Named ? "named" : kind == Kind::Nondimensional ? "nondimensional" : "consistent";
  for (const auto& [name, d] : {std::pair<const char*, Dimension>{"length", Dimension::Length},
                                {"force", Dimension::Force},
                                {"moment", Dimension::Moment},
                                {"stiffness", Dimension::Stiffness},
                                {"compliance", Dimension::Compliance},
                                {"rotational_stiffness", Dimension::RotationalStiffness},
                                {"angle", Dimension::Angle}})
    j[name] = unit(d);
  return j;
}

UnitSystem parseUnits(const JsonReader& r, const nlohmann::json& v, const JsonReader::Pointer& p) {
  UnitSystem u;
  if (v.is_string()) {
    if (v.get<std::string>() == "nondimensional") {
      u.kind = UnitSystem::Kind::Nondimensional;
      return u;
    }
    if (v.get<std::string>() == "consistent") return u;
  }
  if (!v.is_object())
    r.expected(p, v,
               "\"nondimensional\" (lengths in b, forces in k b), \"consistent\" (unnamed) or an object "
               "{\"length\": \"m\", \"force\": \"N\"}");
  r.onlyKeys(v, p, {"length", "force", "mass"});
  u.kind = UnitSystem::Kind::Named;
  for (const char* key : {"length", "force", "mass"}) {
    if (key == std::string("mass") && !v.contains(key)) break;  // optional: only frequencies need it
    const std::string name = r.string(r.required(v, p, key), p / key);
    if (!safeUnitName(name))
      r.expected(p / key, v[key],
                 "a unit name of 1 to 16 bytes: letters, digits, inner spaces and . / ^ * - µ μ · ² ³ (e.g. \"m\", "
                 "\"mm\", \"N\", \"kN\", \"kg\")");
    (key == std::string("length") ? u.length : key == std::string("force") ? u.force : u.mass) = name;
  }
  return u;
}

}  // namespace buckle::scene
