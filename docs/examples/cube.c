/* Renders one hexahedron through cylvol's C ABI (include/cylvol.h) and prints the centre
 * pixel. Build and run from the repository's root:
 *
 *   cargo build --release --lib
 *   cc -std=c11 -I include docs/examples/cube.c target/release/libcylvol.a \
 *      -lpthread -ldl -lm -lrt -lutil -lgcc_s -o cube && ./cube
 */
#include <stdio.h>

#include "cylvol.h"

int main(void) {
  /* The unit cube, its corners in VTK's hexahedron order, a scalar rising from 0 to 7. */
  double points[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  int64_t offsets[2] = {0, 8}, connectivity[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  uint8_t types[1] = {12}; /* VTK_HEXAHEDRON */
  float values[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  CylvolMesh *mesh = NULL;
  CylvolVolume *volume = NULL;
  if (cylvol_mesh_new(points, CYLVOL_VALUE_F64, 8, offsets, connectivity, CYLVOL_INDEX_I64, 8,
                      types, 1, &mesh) != CYLVOL_STATUS_OK ||
      cylvol_mesh_set_scalars(mesh, "p", CYLVOL_POINT_DATA, values, CYLVOL_VALUE_F32, 8, 1, 0) !=
          CYLVOL_STATUS_OK ||
      cylvol_volume_new(mesh, NULL, &volume) != CYLVOL_STATUS_OK) {
    fprintf(stderr, "cylvol: %s\n", cylvol_last_error());
    cylvol_mesh_free(mesh);
    return 1;
  }
  cylvol_mesh_free(mesh); /* the volume keeps what it needs */

  /* Looking down -z at the cube's centre. */
  CylvolCamera camera;
  cylvol_camera_default(&camera);
  camera.eye[0] = 0.5; camera.eye[1] = 0.5; camera.eye[2] = 5.0;
  camera.focal_point[0] = 0.5; camera.focal_point[1] = 0.5; camera.focal_point[2] = 0.5;
  /* Blue to red over the scalar range [0, 7], opacity rising from 0.1 to 0.8 per unit. */
  float rgb[6] = {0, 0, 1, 1, 0, 0}, opacity[2] = {0.1f, 0.8f};
  CylvolTransfer transfer = {rgb, 2, opacity, 2, {0.0, 7.0}, 1.0, NULL, 0, {0.0, 1.0}};
  CylvolRenderParams params;
  cylvol_render_params_default(&params);
  params.width = params.height = 64;
  static uint8_t pixels[64 * 64 * 4];
  if (cylvol_render(volume, &camera, &transfer, &params, NULL, NULL, CYLVOL_PIXELS_RGBA8, pixels,
                    sizeof pixels) != CYLVOL_STATUS_OK) {
    fprintf(stderr, "cylvol: %s\n", cylvol_volume_last_error(volume));
    cylvol_volume_free(volume);
    return 1;
  }
  const uint8_t *centre = pixels + 4 * (32 * 64 + 32);
  printf("cylvol %s: centre pixel RGBA %u %u %u %u\n", cylvol_version(), centre[0], centre[1],
         centre[2], centre[3]);
  cylvol_volume_free(volume);
  return 0;
}
