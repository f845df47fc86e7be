#include "camera/pipeline_plan.h"

namespace wircam::recorder {

std::string PipelinePlan::description() const {
  std::string all;
  for (const auto& stream : streams) all += stream.description;
  return all;
}

}  // namespace wircam::recorder
