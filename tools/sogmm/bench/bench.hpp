// `sogmm bench`: the paper's single-frame comparison (OctoMap, NDT-map,
// fixed-K GMMs, SOGMM) on one frame or a folder of frames.
#pragma once

#include <CLI/CLI.hpp>

#include "cli_common.hpp"

namespace sogmm::tools {
/// Registers the `bench` subcommand (tools/sogmm/command_bench.cpp).
Command add_bench_command(CLI::App& root);
}  // namespace sogmm::tools
