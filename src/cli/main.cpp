// cli/main.cpp — the `vdbsplat` binary: dispatches subcommands, and is the one
// place that turns an Error (or any exception) into "vdbsplat: error: …" and a
// non-zero exit.
#include <exception>
#include <iostream>
#include <new>
#include <string>

#include "cli/commands.h"
#include "util/error.h"

namespace {

const char* kUsage =
    "usage: vdbsplat <command> [options]   (vdbsplat <command> --help for details)\n"
    "\n"
    "commands:\n"
    "  render    render a .vdb grid to PNG or EXR (reference, hybrid, splat, point, ewa, swan, none)\n"
    "  animate   render a camera path (zoom, orbit, keyframes) to frames, with per-frame stats\n"
    "  study     antialiasing study: every mode and view against the reference, HTML report\n"
    "  info      describe every grid in a .vdb file\n"
    "  generate  write a test volume (checkerbox, marschner-lobb, sphere, cloud)\n"
    "  convert   turn a raw volume (x fastest) into a sparse .vdb\n"
    "  tables    regenerate or check the footprint and reindex tables\n"
    "  bench     time hybrid, splat-only and point-only at the standard views\n"
    "  compare   image metrics (PSNR, RMSE) of an image against a reference\n";

int dispatch(const std::string& command, const vdbsplat::cli::Argv& args) {
    using namespace vdbsplat::cli;
    if (command == "render") return runRender(args);
    if (command == "animate") return runAnimate(args);
    if (command == "study") return runStudy(args);
    if (command == "info") return runInfo(args);
    if (command == "generate") return runGenerate(args);
    if (command == "convert") return runConvert(args);
    if (command == "tables") return runTables(args);
    if (command == "bench") return runBench(args);
    if (command == "compare") return runCompare(args);
    throw vdbsplat::Error("unknown command '" + command + "' (try: vdbsplat --help)");
}

/// The message on one line: control characters (a newline in a corrupt file's grid name,
/// say) are written as \n, \t or \xHH, and past 1000 characters it is cut with "…".
std::string oneLine(const std::string& message) {
    static const char* hex = "0123456789abcdef";
    constexpr size_t kMaxChars = 1000;
    std::string out;
    for (const char c : message) {
        if (out.size() >= kMaxChars) return out + "…";
        const auto u = static_cast<unsigned char>(c);
        if (c == '\n') out += "\\n";
        else if (c == '\t') out += "\\t";
        else if (u < 0x20 || u == 0x7f) out += std::string("\\x") + hex[u >> 4] + hex[u & 15];
        else out += c;
    }
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::cerr << kUsage;
        return 2;
    }
    const std::string command = argv[1];
    if (command == "--help" || command == "-h" || command == "help") {
        std::cout << kUsage;
        return 0;
    }
    if (command == "--version") {
        std::cout << "vdbsplat " << VDBSPLAT_VERSION << "\n";
        return 0;
    }
    try {
        return dispatch(command, vdbsplat::cli::Argv(argv + 2, argv + argc));
    } catch (const vdbsplat::Error& e) {
        std::cerr << "vdbsplat: error: " << oneLine(e.what()) << "\n";
    } catch (const std::bad_alloc&) {
        std::cerr << "vdbsplat: error: out of memory\n";
    } catch (const std::exception& e) {
        std::cerr << "vdbsplat: error: " << oneLine(e.what()) << "\n";
    }
    return 1;
}
