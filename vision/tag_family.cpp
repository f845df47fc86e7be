#include "tag_family.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h10.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagCircle49h12.h>
#include <apriltag/tagCustom48h12.h>
#include <apriltag/tagStandard41h12.h>
#include <apriltag/tagStandard52h13.h>

#include <cstdlib>
#include <utility>

namespace wircam::vision {

namespace {

struct FamilyEntry {
  const char* name;
  apriltag_family* (*create)();
  void (*destroy)(apriltag_family*);
};

const FamilyEntry kFamilies[] = {
    {"tag36h11", tag36h11_create, tag36h11_destroy},
    {"tag25h9", tag25h9_create, tag25h9_destroy},
    {"tag16h5", tag16h5_create, tag16h5_destroy},
    {"tag36h10", tag36h10_create, tag36h10_destroy},
    {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
    {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy},
    {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
    {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
};

}  // namespace

const std::vector<std::string>& TagFamily::names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (const auto& entry : kFamilies) all.push_back(entry.name);
    return all;
  }();
  return names;
}

Expected<TagFamily, std::string> TagFamily::create(const std::string& name) {
  for (const auto& entry : kFamilies) {
    if (name == entry.name) return TagFamily(name, entry.create(), entry.destroy);
  }
  std::string known;
  for (const auto& entry : kFamilies) known += std::string(known.empty() ? "" : ", ") + entry.name;
  return unexpected("unknown tag family '" + name + "' (known: " + known + ")");
}

int TagFamily::codeCount() const { return static_cast<int>(family_->ncodes); }
int TagFamily::totalWidth() const { return family_->total_width; }
int TagFamily::borderWidth() const { return family_->width_at_border; }

std::vector<uint8_t> TagFamily::image(int id) const {
  if (id < 0 || id >= codeCount()) return {};
  image_u8_t* picture = apriltag_to_image(family_.get(), id);
  std::vector<uint8_t> cells;
  cells.reserve(static_cast<size_t>(picture->width) * picture->height);
  for (int y = 0; y < picture->height; ++y)
    cells.insert(cells.end(), picture->buf + y * picture->stride,
                 picture->buf + y * picture->stride + picture->width);
  // Debian's libapriltag does not export image_u8_destroy; the image and its
  // buffer come from malloc (common/image_u8.c), so free them as it would.
  std::free(picture->buf);
  std::free(picture);
  return cells;
}

}  // namespace wircam::vision
