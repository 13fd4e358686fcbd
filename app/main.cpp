// The `nebula` command line.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "app/commands.h"
#include "core/error.h"

int main(int argc, char** argv) {
  CLI::App app{
      "nebula: physics simulator and renderer for reflection nebulae.\n"
      "Start with `nebula render --demo -o demo.png`, or `nebula tabulate -o table.h5`."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "nebula 0.1.0");
  nebula::app::add_render_command(app);
  nebula::app::add_truth_command(app);
  nebula::app::add_compare_command(app);
  nebula::app::add_tabulate_command(app);
  nebula::app::add_table_command(app);
  nebula::app::add_slab_command(app);
  nebula::app::add_validate_command(app);
  nebula::app::add_bench_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "nebula: error: %s (see --help)\n", e.what());
    return 2;
  } catch (const nebula::Error& e) {
    std::fprintf(stderr, "nebula: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nebula: internal error: %s\n", e.what());
    return 3;
  }
  return 0;
}
