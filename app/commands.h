#pragma once
// Subcommands of the `nebula` command line; each registers itself on the app.
#include <CLI/CLI.hpp>

namespace nebula::app {

void add_tabulate_command(CLI::App& app);
void add_table_command(CLI::App& app);
void add_slab_command(CLI::App& app);
void add_validate_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_filters_command(CLI::App& app);
void add_spectral_bench(CLI::App* bench);
void add_render_command(CLI::App& app);
void add_truth_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_animate_command(CLI::App& app);
void add_frame_benchmarks(CLI::App* bench);  // `nebula bench animate`, `nebula bench viewer`
void add_sweep_command(CLI::App& app);
void add_reconstruct_command(CLI::App& app);
void add_reconstruct_bench(CLI::App* bench);  // `nebula bench reconstruct` (app/reconstruct_command.cpp)

}  // namespace nebula::app
