// The generated header compiled as C++ (-Wall -Wextra -Werror -pedantic): its declarations
// must be usable from C++ without casts or warnings.
#include <cstdio>
#include <cstring>

#include "cylvol.h"

int main() {
  CylvolRenderParams params;
  cylvol_render_params_default(&params);
  CylvolCamera camera;
  cylvol_camera_default(&camera);
  const char *version = cylvol_version();
  CylvolStatus status = cylvol_mesh_bounds(nullptr, nullptr);
  if (std::strlen(version) == 0 || status != CYLVOL_STATUS_NULL_POINTER ||
      params.path != CYLVOL_PATH_FAST || camera.mode != CYLVOL_CAMERA_LOOK_AT) {
    std::printf("header_cxx: unexpected values\n");
    return 1;
  }
  std::printf("cylvol %s from C++: ok\n", version);
  return 0;
}
