#pragma once

#include <string>

#include "pipeline/carve_pipeline.h"
#include "pipeline/json_writer.h"

namespace raycarve {

// report.json of a carve: the run's identity, every option as used, the masks per photo, the
// colour calibration, bounds, the carve's statistics and levels, the sparse points' distance,
// each stage's seconds, the outputs and the mesh. Fed from the pipeline's stage results.
std::string CarveReportJson(const CarveRequest& request, const CarveRun& run);

// The version of the reports' layout (report.json, holdout.json), written as "schema_version":
// raised whenever a field is renamed, removed or changes its meaning or unit, so that a program
// reading them can tell. 1: the first to carry it (this round's capture, box-wall and sparse-depth
// fields included).
constexpr int kReportSchemaVersion = 1;

// The run's identity at the head of every report: schema_version, raycarve_version, commit,
// command_line and start_time, as keys of the open object.
void WriteRunIdentity(JsonWriter& json);

// The process's peak resident memory so far, in MiB (getrusage).
double ProcessPeakMiB();

}  // namespace raycarve
