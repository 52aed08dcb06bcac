// lacuna — command-line entry point. Every lacuna::Error becomes one line on stderr and exit
// code 2; usage errors exit 2 as well (docs/cli.md).
#include <cstdio>
#include <exception>
#include <iostream>

#include "cli_common.h"
#include "lacuna/error.h"

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
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "lacuna: %s (see --help)\n", e.what());
        return 2;
    } catch (const lacuna::Error& e) {
        std::fprintf(stderr, "lacuna: %s\n", e.what());
        return 2;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "lacuna: out of memory\n");
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "lacuna: internal error: %s\n", e.what());
        return 3;
    }
    return 0;
}
