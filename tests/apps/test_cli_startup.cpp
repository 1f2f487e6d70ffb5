// What `buckle` is as a file (apps/buckle/CMakeLists.txt): with BUCKLE_STATIC_PROGRAM a static
// PIE, so that a short command pays for no loader and no shared library; its unwind tables are
// found through PT_GNU_EH_FRAME (the first exception, CLI11's for --help, sorts nothing). Read
// from the ELF program headers of build/bin/buckle.
#include <catch2/catch.hpp>

#include <elf.h>

#include <fstream>
#include <string>
#include <vector>

#include "cli_helpers.h"
#include "temp_dir.h"

namespace {

struct ElfFacts {
  bool read = false;
  int type = 0;
  bool interpreter = false;  // PT_INTERP: started by the dynamic loader
  bool dynamic = false;      // PT_DYNAMIC
  bool ehFrameHeader = false;
};

ElfFacts elfFacts(const std::string& path) {
  ElfFacts f;
  std::ifstream in(path, std::ios::binary);
  Elf64_Ehdr eh{};
  if (!in.read(reinterpret_cast<char*>(&eh), sizeof eh) || std::string(reinterpret_cast<char*>(eh.e_ident), 4) != "\177ELF" ||
      eh.e_ident[EI_CLASS] != ELFCLASS64 || eh.e_phentsize != sizeof(Elf64_Phdr))
    return f;
  f.type = eh.e_type;
  std::vector<Elf64_Phdr> ph(eh.e_phnum);
  in.seekg(std::streamoff(eh.e_phoff));
  if (!in.read(reinterpret_cast<char*>(ph.data()), std::streamsize(ph.size() * sizeof(Elf64_Phdr)))) return f;
  for (const Elf64_Phdr& p : ph) {
    f.interpreter = f.interpreter || p.p_type == PT_INTERP;
    f.dynamic = f.dynamic || p.p_type == PT_DYNAMIC;
    f.ehFrameHeader = f.ehFrameHeader || p.p_type == PT_GNU_EH_FRAME;
  }
  f.read = true;
  return f;
}

}  // namespace

TEST_CASE("buckle is a static PIE when BUCKLE_STATIC_PROGRAM is on, and still answers --help", "[cli][startup]") {
  const ElfFacts f = elfFacts(buckle::test::kBuckle);
  REQUIRE(f.read);
  CHECK(f.type == ET_DYN);  // position-independent either way (Debian's default PIE)
  CHECK(f.ehFrameHeader);
#if BUCKLE_STATIC_PROGRAM
  CHECK_FALSE(f.interpreter);
#else
  CHECK(f.interpreter);  // the sanitizer build: its runtimes are shared libraries
#endif
  const auto dir = buckle::test::freshDirectory("cli_startup", "help");
  CHECK(buckle::test::exitCode("--help", dir / "help.txt") == 0);
  CHECK(buckle::test::slurp(dir / "help.txt").find("Subcommands:") != std::string::npos);
}
