// lacuna — command-line entry point. Every lacuna::Error becomes one line on stderr and exit
// code 2; usage errors exit 2 as well (docs/cli.md).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "cli_common.h"
#include "dist/comm.h"
#include "frame_flags.h"
#include "lacuna/error.h"

namespace {

// Edit distance, for "did you mean" on a mistyped subcommand.
size_t distance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diag = up;
        }
    }
    return row[b.size()];
}

// CLI11 reports a mistyped subcommand as "A subcommand is required"; name it instead.
void check_subcommand(const CLI::App& app, int argc, char** argv) {
    if (argc < 2 || argv[1][0] == '-') return;
    const std::string word = argv[1];
    std::string names, best;
    size_t best_d = 3;  // suggest only close matches
    for (const CLI::App* s : app.get_subcommands([](const CLI::App*) { return true; })) {
        if (s->get_name() == word) return;
        names += (names.empty() ? "" : ", ") + s->get_name();
        if (const size_t d = distance(word, s->get_name()); d < best_d)
            best_d = d, best = s->get_name();
    }
    throw lacuna::Error("unknown command '" + word + "'" +
                        (best.empty() ? "" : " (did you mean '" + best + "'?)") +
                        "; expected one of: " + names);
}

// --quiet on the app and on every subcommand, so both `lacuna --quiet render ...` and
// `lacuna render ... --quiet` work (cli_common.h: progress and summaries, never errors).
void add_quiet(CLI::App& app) {
    app.add_flag_callback(
        "--quiet,-q", [] { lacuna::cli::set_quiet(true); },
        "No progress lines or summaries on stderr (errors are still printed)");
    for (CLI::App* s : app.get_subcommands([](const CLI::App*) { return true; })) add_quiet(*s);
}

// Under mpirun every rank parses the same flags and fails alike: rank 0 alone prints the line
// and alone ends with the failure's code; the other ranks end with 0. mpirun's status is then
// rank 0's, and rank 0's line always reaches the terminal: when a rank other than 0 ended with
// a non-zero code first, mpirun aborted the job and could drop rank 0's line, still in its pipe.
// (A failure of one rank alone never gets here: it ends the job with its own line and
// MPI_Abort, src/dist.)
int fail(const std::string& line, int code) {
    if (lacuna::dist::launcher_rank() != 0) return 0;
    std::fprintf(stderr, "lacuna: %s\n", line.c_str());
    return code;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"lacuna: direct volume rendering with exact empty-space skipping"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "lacuna 0.1.0");
    lacuna::cli::register_info(app);
    lacuna::cli::register_render(app);
    lacuna::cli::register_generate(app);
    lacuna::cli::register_bench(app);
    lacuna::cli::register_partition(app);
    lacuna::cli::register_serve(app);
    add_quiet(app);
    try {
        check_subcommand(app, argc, argv);
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        return fail(std::string(e.what()) + " (see --help)", 2);
    } catch (const lacuna::FrameError& e) {
        // The library names FrameSpec fields; the user typed flags (frame_flags.cpp).
        return fail(lacuna::cli::flag_of_field(e.field()) + ": " + e.field() + ": " + e.expected(),
                    2);
    } catch (const lacuna::Error& e) {
        return fail(lacuna::cli::with_flag(e.what()), 2);
    } catch (const std::bad_alloc&) {
        return fail("out of memory", 2);
    } catch (const std::exception& e) {
        return fail(std::string("internal error: ") + e.what(), 3);
    }
    return 0;
}
