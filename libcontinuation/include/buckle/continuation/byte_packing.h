// Results as bytes for another process of the same program (the atlas's cells, a workspace map's
// rows under MPI): fixed-size fields copied byte for byte — the receiver is the same program on
// the same kind of machine, so doubles travel bit for bit — and strings and vectors as a length
// and their contents.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace buckle::continuation {

class ByteWriter {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>, "fixed-size fields only");
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void putString(const std::string& s) {
    put(std::uint64_t(s.size()));
    bytes_ += s;
  }
  template <class Derived>
  void putVector(const Eigen::DenseBase<Derived>& v) {
    put(std::uint64_t(v.size()));
    for (Eigen::Index i = 0; i < v.size(); ++i) put(double(v.derived().coeff(i)));
  }
  const std::string& bytes() const { return bytes_; }
  std::string release() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

/// Reads what a ByteWriter wrote; throws std::runtime_error ("<what>: the packed data ends
/// early") instead of reading past the end.
class ByteReader {
 public:
  ByteReader(const std::string& bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}
  bool done() const { return at_ == bytes_.size(); }
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>, "fixed-size fields only");
    T v;
    need(sizeof v);
    std::memcpy(&v, bytes_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  std::string getString() {
    const auto n = get<std::uint64_t>();
    need(n);
    std::string s = bytes_.substr(at_, size_t(n));
    at_ += size_t(n);
    return s;
  }
  Eigen::VectorXd getVector() {
    const auto n = get<std::uint64_t>();
    if (n > (bytes_.size() - at_) / sizeof(double)) fail("the packed data ends early");
    Eigen::VectorXd v(static_cast<Eigen::Index>(n));
    for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = get<double>();
    return v;
  }
  [[noreturn]] void fail(const std::string& why) const { throw std::runtime_error(what_ + ": " + why); }

 private:
  void need(std::uint64_t n) const {
    if (n > bytes_.size() - at_) fail("the packed data ends early");
  }
  const std::string& bytes_;
  std::string what_;
  size_t at_ = 0;
};

}  // namespace buckle::continuation
