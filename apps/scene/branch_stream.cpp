#include "scene/branch_stream.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace buckle::scene {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& what) {
  throw std::runtime_error(what + ": " + std::strerror(errno));
}

// An anonymous file in `dir`: created under a unique name and unlinked at once.
int anonymousFile(const std::string& dir) {
  std::string name = (fs::path(dir) / ".buckle-rows-XXXXXX").string();
  const int fd = ::mkstemp(name.data());
  if (fd < 0) fail("cannot create a spool file in " + dir);
  ::unlink(name.c_str());
  return fd;
}

void writeAll(int fd, const char* data, size_t bytes, const std::string& file) {
  while (bytes > 0) {
    const ssize_t w = ::write(fd, data, bytes);
    if (w < 0) {
      if (errno == EINTR) continue;
      fail("cannot write " + file);
    }
    data += w;
    bytes -= size_t(w);
  }
}

}  // namespace

BranchStream::BranchStream(const Scene& scene, const std::string& directory, size_t inMemoryBytes)
    : layout_(scene), directory_(directory), inMemoryBytes_(inMemoryBytes) {}

BranchStream::~BranchStream() {
  if (csv_.fd >= 0) ::close(csv_.fd);
  if (npy_.fd >= 0) ::close(npy_.fd);
}

void BranchStream::append(Spool& spool, const std::string& bytes) {
  if (spool.fd < 0 && spool.memory.size() + bytes.size() <= inMemoryBytes_) {
    // its whole capacity at once: address space only until written, and never moved as it fills
    if (spool.memory.capacity() < inMemoryBytes_) spool.memory.reserve(inMemoryBytes_);
    spool.memory += bytes;
  } else {
    if (spool.fd < 0) {
      spool.fd = anonymousFile(directory_);
      writeAll(spool.fd, spool.memory.data(), spool.memory.size(), "the spool file of branches.csv");
      std::string().swap(spool.memory);
    }
    writeAll(spool.fd, bytes.data(), bytes.size(), "the spool file of branches.csv");
  }
  spool.size += bytes.size();
}

void BranchStream::add(size_t c, const CaseResult& cr, const std::vector<mechanics::PointReport>& points) {
  if (cases_.size() <= c) cases_.resize(c + 1);
  Piece piece;
  piece.branch = points.empty() ? -1 : points.front().branch;
  piece.rows = points.size();
  std::string& text = rowsText_;
  text.clear();
  text.reserve(points.size() * layout_.rowBytes());
  for (const mechanics::PointReport& p : points) layout_.appendRow(text, c, cr, p);
  piece.csvOffset = csv_.size;
  piece.csvBytes = text.size();
  append(csv_, text);
  if (layout_.sideFile()) {
    text.clear();
    text.reserve(points.size() * layout_.jointAnglesRowBytes());
    for (const mechanics::PointReport& p : points) layout_.appendJointAngles(text, p);
    piece.npyOffset = npy_.size;
    piece.npyBytes = text.size();
    append(npy_, text);
  }
  cases_[c].push_back(piece);
  rows_ += points.size();
  // a long chain's branch of thousands of rows is hundreds of megabytes: not kept for the next
  if (text.capacity() > inMemoryBytes_) std::string().swap(text);
}

void BranchStream::sortByBranch(size_t c, size_t first) {
  if (c >= cases_.size() || first >= cases_[c].size()) return;
  std::stable_sort(cases_[c].begin() + long(first), cases_[c].end(),
                   [](const Piece& a, const Piece& b) { return a.branch < b.branch; });
}

std::vector<int> BranchStream::branchIds(size_t c) const {
  std::vector<int> ids;
  if (c < cases_.size())
    for (const Piece& p : cases_[c]) ids.insert(ids.end(), p.rows, p.branch);
  return ids;
}

void BranchStream::copy(const Spool& spool, size_t offset, size_t bytes, int to, const std::string& file) const {
  if (spool.fd < 0) {
    writeAll(to, spool.memory.data() + offset, bytes, file);
    return;
  }
  // In the kernel where the file system can (the spool lies beside the output): no round trip of
  // hundreds of megabytes through this process; read and write what it leaves.
  while (bytes > 0) {
    loff_t from = loff_t(offset);
    const ssize_t r = ::copy_file_range(spool.fd, &from, to, nullptr, bytes, 0);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;
    offset += size_t(r);
    bytes -= size_t(r);
  }
  if (bytes == 0) return;
  std::string buffer(std::min<size_t>(bytes, size_t(8) << 20), '\0');
  while (bytes > 0) {
    const ssize_t r = ::pread(spool.fd, buffer.data(), std::min(bytes, buffer.size()), off_t(offset));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) fail("cannot read back the rows of " + file);
    writeAll(to, buffer.data(), size_t(r), file);
    offset += size_t(r);
    bytes -= size_t(r);
  }
}

void BranchStream::write(const std::string& dir) const {
  const auto output = [](const fs::path& file) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) fail("cannot write " + file.string());
    return fd;
  };
  const fs::path csvFile = fs::path(dir) / "branches.csv";
  int fd = output(csvFile);
  try {
    const std::string header = layout_.header();
    writeAll(fd, header.data(), header.size(), csvFile.string());
    for (const std::vector<Piece>& pieces : cases_)
      for (const Piece& p : pieces) copy(csv_, p.csvOffset, p.csvBytes, fd, csvFile.string());
    if (layout_.sideFile()) {
      ::close(fd);
      fd = -1;
      const fs::path npyFile = fs::path(dir) / "joint_angles.npy";
      fd = output(npyFile);
      const std::string header = layout_.jointAnglesHeader(rows_);
      writeAll(fd, header.data(), header.size(), npyFile.string());
      for (const std::vector<Piece>& pieces : cases_)
        for (const Piece& p : pieces) copy(npy_, p.npyOffset, p.npyBytes, fd, npyFile.string());
    }
  } catch (...) {
    if (fd >= 0) ::close(fd);
    throw;
  }
  if (fd >= 0 && ::close(fd) != 0) fail("cannot write the rows of branches.csv");
}

}  // namespace buckle::scene
