// cli/main.cpp — the `vdbsplat` binary: declares every subcommand on one CLI11 app, parses the
// command line, runs the chosen command, and is the one place that turns an Error, a CLI11
// parse error (or any exception) into "vdbsplat: error: …" on one line and exit status 1.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "util/error.h"

namespace {

using namespace vdbsplat::cli;

const char* kDescription =
    "usage: vdbsplat <command> [options]   (vdbsplat <command> --help for details)\n"
    "\n"
    "Renders sparse OpenVDB volumes with points and splats (docs/usage.md has every flag).";

/// One subcommand: its name and its two entry points (its summary is the first line of the
/// description its declare function gives).
struct Command {
    const char* name;
    void (*declare)(CLI::App&);
    int (*run)(const Args&);
};

const Command kCommands[] = {
    {"render", declareRender, runRender},       {"animate", declareAnimate, runAnimate},
    {"study", declareStudy, runStudy},          {"info", declareInfo, runInfo},
    {"generate", declareGenerate, runGenerate}, {"convert", declareConvert, runConvert},
    {"tables", declareTables, runTables},       {"bench", declareBench, runBench},
    {"compare", declareCompare, runCompare},
};

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

/// Parses the command line and runs the command it names; help and version exit 0.
int parseAndRun(CLI::App& app, int argc, char** argv) {
    try {
        parseWords(app, std::vector<std::string>(argv + 1, argv + argc));
    } catch (const CLI::CallForHelp&) {
        std::cout << app.help();  // the chosen command's help, or the list of commands
        return 0;
    } catch (const CLI::CallForVersion& v) {
        std::cout << v.what() << "\n";
        return 0;
    } catch (const CLI::ParseError& e) {
        throw vdbsplat::Error(parseErrorMessage(app, e));
    }
    for (const CLI::App* sub : app.get_subcommands())
        for (const Command& c : kCommands)
            if (sub->get_name() == c.name) return c.run(Args(*sub, std::vector<std::string>(argv + 2, argv + argc)));
    throw vdbsplat::Error("no command given (try: vdbsplat --help)");
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{kDescription, "vdbsplat"};
    useHelpLayout(app);
    app.set_version_flag("--version", std::string("vdbsplat ") + VDBSPLAT_VERSION, "print the version and exit");
    app.require_subcommand(1);
    for (const Command& c : kCommands) {
        CLI::App* sub = app.add_subcommand(c.name)->group("commands");
        sub->get_help_ptr()->group("options");  // its --help, listed with the command's own flags
        c.declare(*sub);
    }
    if (argc < 2) {
        std::cerr << app.help();
        return 2;
    }
    if (std::string(argv[1]) == "help") {
        std::cout << app.help();
        return 0;
    }
    try {
        return parseAndRun(app, argc, argv);
    } catch (const vdbsplat::Error& e) {
        std::cerr << "vdbsplat: error: " << oneLine(e.what()) << "\n";
    } catch (const std::bad_alloc&) {
        std::cerr << "vdbsplat: error: out of memory\n";
    } catch (const std::exception& e) {
        std::cerr << "vdbsplat: error: " << oneLine(e.what()) << "\n";
    }
    return 1;
}
