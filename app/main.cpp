// The `nebula` command line: one file per command (app/*_command.cpp), each
// parsing its options, calling the libraries and printing.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstring>
#include <string>

#include "app/commands.h"
#include "core/error.h"

namespace {

// The known command closest to `word` by edit distance, when it is close.
std::string nearest(const std::string& word, const std::vector<const CLI::App*>& commands) {
  std::string best;
  size_t best_distance = 3;  // suggest only within two edits
  for (const CLI::App* c : commands) {
    const std::string& name = c->get_name();
    std::vector<size_t> row(name.size() + 1);
    for (size_t j = 0; j <= name.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= word.size(); ++i) {
      size_t diagonal = row[0];
      row[0] = i;
      for (size_t j = 1; j <= name.size(); ++j) {
        const size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (word[i - 1] == name[j - 1] ? 0 : 1)});
        diagonal = up;
      }
    }
    if (row[name.size()] < best_distance) {
      best_distance = row[name.size()];
      best = name;
    }
  }
  return best;
}

// The first argument when it is neither an option nor a command: said
// plainly, instead of CLI11's "A subcommand is required".
bool unknown_command(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return false;
  const std::vector<const CLI::App*> commands = app.get_subcommands([](const CLI::App*) { return true; });
  std::string list;
  for (const CLI::App* c : commands) {
    if (c->get_name() == argv[1]) return false;
    list += (list.empty() ? "" : ", ") + c->get_name();
  }
  const std::string suggestion = nearest(argv[1], commands);
  std::fprintf(stderr, "nebula: error: '%s' is not a command%s (commands: %s; see --help)\n", argv[1],
               suggestion.empty() ? "" : ("; did you mean '" + suggestion + "'?").c_str(), list.c_str());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "nebula: physics simulator and renderer for reflection nebulae.\n"
      "Start with `nebula render --demo -o demo.png`, or `nebula tabulate -o table.h5`."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "nebula 0.1.0");
  nebula::app::add_render_command(app);
  nebula::app::add_truth_command(app);
  nebula::app::add_animate_command(app);
  nebula::app::add_compare_command(app);
  nebula::app::add_sweep_command(app);
  nebula::app::add_reconstruct_command(app);
  nebula::app::add_tabulate_command(app);
  nebula::app::add_table_command(app);
  nebula::app::add_slab_command(app);
  nebula::app::add_validate_command(app);
  nebula::app::add_bench_command(app);
  nebula::app::add_filters_command(app);
  if (unknown_command(app, argc, argv)) return 2;
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
  } catch (const nebula::ParameterError& e) {
    // A parameter no command mapped to an option of its own.
    std::fprintf(stderr, "nebula: error: %s\n",
                 e.parameter() == "backend" ? ("--backend: " + e.reason()).c_str() : e.what());
    return 1;
  } catch (const nebula::Error& e) {
    std::fprintf(stderr, "nebula: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nebula: internal error: %s\n", e.what());
    return 3;
  }
  return 0;
}
