// An AprilTag family of the AprilTag 3 library, chosen by name and released
// with the right destroy function.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "common/expected.h"

struct apriltag_family;

namespace wircam::vision {

class TagFamily {
 public:
  // "tag36h11", "tag25h9", "tag16h5", "tag36h10", "tagCircle21h7", "tagCircle49h12",
  // "tagCustom48h12", "tagStandard41h12", "tagStandard52h13".
  static Expected<TagFamily, std::string> create(const std::string& name);
  static const std::vector<std::string>& names();

  const std::string& name() const { return name_; }
  apriltag_family* get() const { return family_.get(); }
  int codeCount() const;

  // The tag as the printed pattern, one byte per cell (0 black, 255 white),
  // totalWidth() cells square; the detector's corners are those of the
  // centred borderWidth() square.
  std::vector<uint8_t> image(int id) const;
  int totalWidth() const;
  int borderWidth() const;

 private:
  using Destroy = void (*)(apriltag_family*);
  TagFamily(std::string name, apriltag_family* family, Destroy destroy)
      : name_(std::move(name)), family_(family, destroy) {}

  std::string name_;
  std::shared_ptr<apriltag_family> family_;
};

}  // namespace wircam::vision
