// How the test programs are linked: ctest starts one process per test, so whatever a
// program does before main() is paid once for every test in every build.
#include <elf.h>

#include <gtest/gtest.h>

#include <fstream>

// Only the ASan+UBSan build links its programs without PIE (cmake/SpindleOptions.cmake).
#if defined(__SANITIZE_ADDRESS__)

namespace {

// ET_EXEC for a program loaded at its link-time address, ET_DYN for a position
// independent one, which the loader relocates at every start.
int running_program_elf_type() {
    std::ifstream program("/proc/self/exe", std::ios::binary);
    Elf64_Ehdr header{};
    program.read(reinterpret_cast<char*>(&header), sizeof header);
    if (!program) return -1;
    return header.e_type;
}

}  // namespace

TEST(ProgramStart, AddressSanitizerBuildLinksProgramsAtAFixedAddress) {
    EXPECT_EQ(running_program_elf_type(), ET_EXEC)
        << "an ASan+UBSan program linked as PIE relocates every check record at each start";
}

#endif
