#pragma once

namespace wircam::recorder {

// Makes GLib's slice allocator plain malloc, as GLib 2.76 and later always
// are, by starting the process again with G_SLICE=always-malloc. Returns at
// once where that is already so (a newer GLib, or G_SLICE set by the user or
// by the first start).
void useMallocForSlices(char** argv);

}  // namespace wircam::recorder
