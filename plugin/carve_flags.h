#pragma once

#include <string>

#include "pipeline/carve_request.h"
#include "plugin/option_parser.h"

namespace raycarve {

// The flag groups the commands share, each registered once here.

// Where a project is: every command that reads a workspace takes these. `output_path` and
// `model_index` may be null (the command has no such flag).
struct WorkspaceFlags {
  std::string* workspace_path = nullptr;
  std::string* input_path = nullptr;
  std::string* image_path = nullptr;
  std::string* output_path = nullptr;
  int* model_index = nullptr;
};
void AddWorkspaceFlags(OptionParser* parser, const WorkspaceFlags& flags);

// The volume's bounds (BoundsRequest): the sparse points' filters, or --bbox.
void AddBoundsFlags(OptionParser* parser, BoundsRequest* bounds);

// The carve pipeline's flags, shared by `carve`, `holdout` and `benchmark`, grouped by stage:
// workspace, photos and masks, bounds, carve, levels of detail, mesh and cloud, threads.
// AddCarveFlags declares them (the enum-valued ones as text, into `text`); ApplyCarveFlags
// converts and checks them, then FinishCarveRequest (InputError on bad values).
struct CarveFlagText {
  std::string threshold = "auto";
  std::string pattern_threshold = "auto";
  std::string consistency;
  std::string vis_lookup;
  std::string method;
  std::string order;
  std::string decision;
  std::string background = "auto";
  std::string spread_floor = "auto";
  std::string threshold_views = "auto";
};
void AddCarveFlags(OptionParser* parser, CarveRequest* request, CarveFlagText* text);
// `parser` (after Parse) says which flags were given: a --resolution not given may be lowered to
// what the photos resolve (CarveRequest::resolution_given).
void ApplyCarveFlags(const OptionParser& parser, const CarveFlagText& text, CarveRequest* request);

// The carve options a user changes first: what `--help` shows of carve and holdout.
extern const char* const kBasicCarveFlags[10];

}  // namespace raycarve
