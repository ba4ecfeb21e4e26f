/* The C ABI from C: meshes built here (a unit cube of hexahedra; an annulus sector of
 * hexahedra with a wedge and a tetrahedron), pixels checked against the Beer–Lambert law,
 * missing rays, RGBA8 against float output and the two camera modes, and every status a
 * caller can provoke, each with a non-empty detail. Prints "N passed, N failed". */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cylvol.h"

static int passed = 0;
static int failed = 0;

#define CHECK(cond, ...)                                  \
  do {                                                    \
    if (cond) {                                           \
      ++passed;                                           \
    } else {                                              \
      ++failed;                                           \
      printf("FAILED %s:%d: %s: ", __FILE__, __LINE__, #cond); \
      printf(__VA_ARGS__);                                \
      printf("\n");                                       \
    }                                                     \
  } while (0)

/* A call must fail with `expected` and leave a detail naming the function. */
static void expect_status(CylvolStatus got, CylvolStatus expected, const char *function,
                          const char *what) {
  const char *detail = cylvol_last_error();
  CHECK(got == expected, "%s: status %d (%s), expected %d; detail: %s", what, (int)got,
        cylvol_status_message(got), (int)expected, detail);
  if (expected != CYLVOL_STATUS_OK) {
    CHECK(detail != NULL && strlen(detail) > 0, "%s: empty last error", what);
    CHECK(detail != NULL && strncmp(detail, function, strlen(function)) == 0,
          "%s: detail '%s' does not name %s", what, detail, function);
  }
}

/* ---- meshes ---------------------------------------------------------------------------- */

typedef struct Arrays {
  double *points;
  size_t n_points;
  int64_t *offsets;
  int64_t *connectivity;
  size_t connectivity_len;
  uint8_t *types;
  size_t n_cells;
} Arrays;

static void arrays_init(Arrays *a, size_t max_points, size_t max_cells) {
  a->points = calloc(max_points * 3, sizeof(double));
  a->offsets = calloc(max_cells + 1, sizeof(int64_t));
  a->connectivity = calloc(max_cells * 8, sizeof(int64_t));
  a->types = calloc(max_cells, sizeof(uint8_t));
  a->n_points = a->connectivity_len = a->n_cells = 0;
}

static void arrays_free(Arrays *a) {
  free(a->points);
  free(a->offsets);
  free(a->connectivity);
  free(a->types);
}

static int64_t add_point(Arrays *a, double x, double y, double z) {
  a->points[3 * a->n_points] = x;
  a->points[3 * a->n_points + 1] = y;
  a->points[3 * a->n_points + 2] = z;
  return (int64_t)a->n_points++;
}

static void add_cell(Arrays *a, uint8_t type, const int64_t *ids, size_t n) {
  memcpy(a->connectivity + a->connectivity_len, ids, n * sizeof(int64_t));
  a->connectivity_len += n;
  a->types[a->n_cells++] = type;
  a->offsets[a->n_cells] = (int64_t)a->connectivity_len;
}

/* The unit cube cut into n^3 hexahedra. */
static void cube(Arrays *a, size_t n) {
  size_t m = n + 1, i, j, k;
  arrays_init(a, m * m * m, n * n * n);
  for (k = 0; k < m; ++k)
    for (j = 0; j < m; ++j)
      for (i = 0; i < m; ++i) add_point(a, (double)i / n, (double)j / n, (double)k / n);
#define ID(i, j, k) ((int64_t)((i) + m * ((j) + m * (k))))
  for (k = 0; k < n; ++k)
    for (j = 0; j < n; ++j)
      for (i = 0; i < n; ++i) {
        int64_t ids[8] = {ID(i, j, k),         ID(i + 1, j, k),         ID(i + 1, j + 1, k),
                          ID(i, j + 1, k),     ID(i, j, k + 1),         ID(i + 1, j, k + 1),
                          ID(i + 1, j + 1, k + 1), ID(i, j + 1, k + 1)};
        add_cell(a, 12, ids, 8);
      }
#undef ID
}

/* 2 x 3 hexahedra of an annulus sector about z (r 1..2, theta 0..0.9, h 0..0.5), with a wedge
 * and a tetrahedron on top. */
static void sector(Arrays *a) {
  size_t nr = 2, nt = 3, i, j, k;
  int64_t top, apex;
  arrays_init(a, 64, 16);
  for (k = 0; k < 2; ++k)
    for (j = 0; j <= nt; ++j)
      for (i = 0; i <= nr; ++i) {
        double r = 1.0 + 0.5 * i, t = 0.3 * j;
        add_point(a, r * cos(t), r * sin(t), 0.5 * k);
      }
#define ID(i, j, k) ((int64_t)((i) + (nr + 1) * ((j) + (nt + 1) * (k))))
  for (j = 0; j < nt; ++j)
    for (i = 0; i < nr; ++i) {
      int64_t ids[8] = {ID(i, j, 0), ID(i + 1, j, 0), ID(i + 1, j + 1, 0), ID(i, j + 1, 0),
                        ID(i, j, 1), ID(i + 1, j, 1), ID(i + 1, j + 1, 1), ID(i, j + 1, 1)};
      add_cell(a, 12, ids, 8);
    }
  {
    int64_t base[3] = {ID(0, 0, 1), ID(1, 0, 1), ID(0, 1, 1)};
    int64_t wedge[6];
    top = (int64_t)a->n_points;
    for (i = 0; i < 3; ++i) {
      const double *p = a->points + 3 * base[i];
      add_point(a, p[0], p[1], p[2] + 0.5);
    }
    /* VTK's numbering: the base 0, 1, 2 turns away from the top (right-hand rule). */
    wedge[0] = base[0]; wedge[1] = base[2]; wedge[2] = base[1];
    wedge[3] = top; wedge[4] = top + 2; wedge[5] = top + 1;
    add_cell(a, 13, wedge, 6);
  }
  apex = add_point(a, 1.75 * cos(0.75), 1.75 * sin(0.75), 0.9);
  {
    int64_t tet[4] = {ID(1, 2, 1), ID(2, 2, 1), ID(1, 3, 1), apex};
    add_cell(a, 10, tet, 4);
  }
#undef ID
}

static CylvolStatus mesh_new(const Arrays *a, CylvolMesh **out) {
  return cylvol_mesh_new(a->points, CYLVOL_VALUE_F64, a->n_points, a->offsets, a->connectivity,
                         CYLVOL_INDEX_I64, a->connectivity_len, a->types, a->n_cells, out);
}

/* A mesh with the point scalar x + 2y + z. */
static CylvolMesh *mesh_with_scalars(const Arrays *a) {
  CylvolMesh *mesh = NULL;
  size_t i;
  double *values = malloc(a->n_points * sizeof(double));
  CylvolStatus s = mesh_new(a, &mesh);
  CHECK(s == CYLVOL_STATUS_OK && mesh != NULL, "mesh_new: %s", cylvol_last_error());
  for (i = 0; i < a->n_points; ++i)
    values[i] = a->points[3 * i] + 2.0 * a->points[3 * i + 1] + a->points[3 * i + 2];
  s = cylvol_mesh_set_scalars(mesh, "s", CYLVOL_POINT_DATA, values, CYLVOL_VALUE_F64,
                              a->n_points, 1, 0);
  CHECK(s == CYLVOL_STATUS_OK, "set_scalars: %s", cylvol_last_error());
  free(values); /* copied */
  return mesh;
}

static CylvolVolume *volume_new(const CylvolMesh *mesh, CylvolStructure structure) {
  CylvolBuildParams p;
  CylvolVolume *v = NULL;
  CylvolStatus s;
  cylvol_build_params_default(&p);
  p.structure = structure;
  s = cylvol_volume_new(mesh, &p, &v);
  CHECK(s == CYLVOL_STATUS_OK && v != NULL, "volume_new: %s", cylvol_last_error());
  return v;
}

static const float constant_rgb[6] = {1.0f, 0.5f, 0.25f, 1.0f, 0.5f, 0.25f};
static float constant_opacity[2] = {0.3f, 0.3f};

static CylvolTransfer constant_transfer(void) {
  CylvolTransfer t;
  memset(&t, 0, sizeof t);
  t.rgb = constant_rgb;
  t.n_color = 2;
  t.opacity = constant_opacity;
  t.n_opacity = 2;
  t.range[0] = 0.0;
  t.range[1] = 4.0;
  t.unit_distance = 1.0;
  t.gradient_opacity = NULL;
  return t;
}

/* Parallel rays down -z through the cube's centre; half height 0.75. */
static CylvolCamera down_z(void) {
  CylvolCamera c;
  cylvol_camera_default(&c);
  c.eye[0] = 0.5; c.eye[1] = 0.5; c.eye[2] = 3.0;
  c.focal_point[0] = 0.5; c.focal_point[1] = 0.5; c.focal_point[2] = 0.5;
  c.parallel = 1;
  c.parallel_scale = 0.75;
  return c;
}

/* ---- pixels ------------------------------------------------------------------------------ */

static void test_beer_lambert_and_formats(void) {
  Arrays a;
  CylvolMesh *mesh;
  CylvolVolume *v;
  CylvolCamera camera = down_z();
  CylvolTransfer t = constant_transfer();
  CylvolRenderParams p;
  CylvolRenderStats stats;
  enum { W = 8, H = 8 };
  float f[W * H * 4], depth[W * H];
  uint8_t bytes[W * H * 4];
  size_t i, j, k;
  double expected = 1.0 - pow(1.0 - 0.3, 1.0 / 1.0); /* path length 1, unit distance 1 */
  CylvolStatus s;

  cube(&a, 4);
  mesh = mesh_with_scalars(&a);
  v = volume_new(mesh, CYLVOL_STRUCTURE_AUTO);
  cylvol_mesh_free(mesh); /* the volume has its own copy */
  cylvol_render_params_default(&p);
  p.width = W;
  p.height = H;
  s = cylvol_render(v, &camera, &t, &p, NULL, depth, CYLVOL_PIXELS_RGBA_F32, f, W * H * 4);
  CHECK(s == CYLVOL_STATUS_OK, "render: %s", cylvol_volume_last_error(v));
  for (j = 0; j < H; ++j)
    for (i = 0; i < W; ++i) {
      double x = ((i + 0.5) / W * 2.0 - 1.0) * 0.75, y = (1.0 - (j + 0.5) / H * 2.0) * 0.75;
      size_t at = j * W + i;
      if (fabs(x) < 0.5 && fabs(y) < 0.5) {
        CHECK(fabs(f[4 * at + 3] - expected) < 1e-5, "pixel %zu,%zu alpha %g, Beer-Lambert %g", i,
              j, f[4 * at + 3], expected);
        CHECK(fabs(f[4 * at] - f[4 * at + 3]) < 1e-6, "premultiplied red %g", f[4 * at]);
        CHECK(isinf(depth[at]), "alpha never reaches 0.5: depth %g", depth[at]);
      } else {
        CHECK(f[4 * at] == 0 && f[4 * at + 1] == 0 && f[4 * at + 2] == 0 && f[4 * at + 3] == 0,
              "pixel %zu,%zu misses the cube but is not 0", i, j);
      }
    }
  s = cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA8, bytes, sizeof bytes);
  CHECK(s == CYLVOL_STATUS_OK, "render RGBA8: %s", cylvol_last_error());
  for (k = 0; k < W * H * 4; ++k) {
    long want = lround(fmin(fmax(f[k], 0.0f), 1.0f) * 255.0);
    CHECK(bytes[k] == want, "RGBA8[%zu] = %d, F32 %g", k, bytes[k], f[k]);
  }
  /* Gradient opacity: the field x + 2y + z has |grad| = sqrt(6) everywhere; a factor ramp 0..1
   * over [0, 2 sqrt(6)] halves the opacity per unit distance: alpha = 0.15 over length 1. */
  {
    static const float ramp[2] = {0.0f, 1.0f};
    CylvolTransfer tg = t;
    float g[W * H * 4];
    size_t centre = (H / 2) * W + W / 2;
    tg.gradient_opacity = ramp;
    tg.n_gradient_opacity = 2;
    tg.gradient_range[0] = 0.0;
    tg.gradient_range[1] = 2.0 * sqrt(6.0);
    s = cylvol_render(v, &camera, &tg, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, g, W * H * 4);
    CHECK(s == CYLVOL_STATUS_OK, "render gradient opacity: %s", cylvol_last_error());
    CHECK(fabs(g[4 * centre + 3] - 0.15) < 1e-5, "gradient opacity alpha %g, expected 0.15",
          g[4 * centre + 3]);
    CHECK(g[3] == 0.0f, "corner misses");
  }
  CHECK(cylvol_volume_render_stats(v, &stats) == CYLVOL_STATUS_OK, "stats");
  CHECK(stats.rays == W * H && stats.samples > 0 && stats.samples_located > 0 &&
            stats.hex_tests > 0,
        "stats %llu rays, %llu samples", (unsigned long long)stats.rays,
        (unsigned long long)stats.samples);

  /* The same picture through matrices (VTK's ortho: near 0.1, far 10), in VTK's row order. */
  {
    CylvolCamera m;
    float g[W * H * 4], zbuf[W * H];
    double n = 0.1, fa = 10.0, max = 0.0;
    memset(&m, 0, sizeof m);
    m.mode = CYLVOL_CAMERA_MATRICES;
    /* view: eye (0.5, 0.5, 3) looking down -z, up +y: x - 0.5, y - 0.5, z - 3 */
    m.view[0] = 1; m.view[3] = -0.5;
    m.view[5] = 1; m.view[7] = -0.5;
    m.view[10] = 1; m.view[11] = -3.0;
    m.view[15] = 1;
    m.projection[0] = 1.0 / 0.75;
    m.projection[5] = 1.0 / 0.75;
    m.projection[10] = -2.0 / (fa - n);
    m.projection[11] = -(fa + n) / (fa - n);
    m.projection[15] = 1;
    p.rows_bottom_up = 1;
    s = cylvol_render(v, &m, &t, &p, NULL, zbuf, CYLVOL_PIXELS_RGBA_F32, g, W * H * 4);
    CHECK(s == CYLVOL_STATUS_OK, "render matrices: %s", cylvol_last_error());
    for (j = 0; j < H; ++j)
      for (i = 0; i < W * 4; ++i) {
        double d = fabs(g[(H - 1 - j) * W * 4 + i] - f[j * W * 4 + i]);
        if (d > max) max = d;
      }
    CHECK(max < 1e-5, "matrices vs look-at: %g", max);
    for (k = 0; k < W * H; ++k) CHECK(zbuf[k] == 1.0f, "window depth %g (never 0.5)", zbuf[k]);
    /* Geometry at the near plane (window depth 0) hides everything. */
    for (k = 0; k < W * H; ++k) zbuf[k] = 0.0f;
    s = cylvol_render(v, &m, &t, &p, zbuf, NULL, CYLVOL_PIXELS_RGBA_F32, g, W * H * 4);
    CHECK(s == CYLVOL_STATUS_OK, "render depth_in: %s", cylvol_last_error());
    for (k = 0; k < W * H * 4; ++k) CHECK(g[k] == 0.0f, "hidden pixel %g", g[k]);
  }
  cylvol_volume_free(v);
  arrays_free(&a);
}

static void test_mixed_cells(void) {
  Arrays a;
  CylvolMesh *mesh;
  CylvolVolume *v;
  CylvolCamera camera;
  CylvolTransfer t = constant_transfer();
  CylvolRenderParams p;
  CylvolBuildStats build;
  size_t np = 0, nc = 0, k;
  double bounds[6], range[2];
  enum { W = 16, H = 12 };
  float f[W * H * 4], bounded[W * H * 4];
  float ramp[3] = {0.0f, 0.4f, 0.8f};
  int seen = 0;
  double largest = 0.0;
  CylvolRenderStats stats;

  sector(&a);
  mesh = mesh_with_scalars(&a);
  CHECK(cylvol_mesh_counts(mesh, &np, &nc) == CYLVOL_STATUS_OK && np == a.n_points && nc == 8,
        "counts %zu %zu", np, nc);
  CHECK(cylvol_mesh_bounds(mesh, bounds) == CYLVOL_STATUS_OK && bounds[5] == 1.0 &&
            bounds[4] == 0.0,
        "bounds z %g..%g", bounds[4], bounds[5]);
  CHECK(cylvol_mesh_scalar_range(mesh, range) == CYLVOL_STATUS_OK && range[1] > range[0],
        "range");
  v = volume_new(mesh, CYLVOL_STRUCTURE_AUTO);
  CHECK(cylvol_volume_build_stats(v, &build) == CYLVOL_STATUS_OK, "build stats");
  CHECK(build.structure != CYLVOL_STRUCTURE_AUTO && build.cells == 8 && build.bytes > 0,
        "built %d", (int)build.structure);
  cylvol_camera_default(&camera);
  camera.eye[0] = 1.0; camera.eye[1] = 0.6; camera.eye[2] = 5.0;
  camera.focal_point[0] = 1.0; camera.focal_point[1] = 0.6; camera.focal_point[2] = 0.5;
  cylvol_render_params_default(&p);
  p.width = W;
  p.height = H;
  p.shading = 1;
  t.range[0] = range[0];
  t.range[1] = range[1];
  t.opacity = ramp;
  t.n_opacity = 3;
  CHECK(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, f, W * H * 4) ==
            CYLVOL_STATUS_OK,
        "render: %s", cylvol_last_error());
  for (k = 0; k < W * H; ++k) seen += f[4 * k + 3] > 0.01f;
  CHECK(seen > 10, "only %d pixels see the sector", seen);
  /* A clipping plane keeping z >= 2 (above the sector) leaves nothing to draw; more planes
     than CYLVOL_MAX_CLIP_PLANES are refused. */
  p.clip_plane_count = 1;
  p.clip_planes[0][2] = 1.0;
  p.clip_planes[0][3] = -2.0;
  CHECK(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, f, W * H * 4) ==
            CYLVOL_STATUS_OK,
        "clipped render: %s", cylvol_last_error());
  for (k = 0; k < W * H * 4; ++k) CHECK(f[k] == 0.0f, "clipped pixel %g", f[k]);
  p.clip_plane_count = CYLVOL_MAX_CLIP_PLANES + 1;
  CHECK(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, f, W * H * 4) ==
            CYLVOL_STATUS_INVALID_ARGUMENT,
        "7 clipping planes");
  /* The march reach: 6 cells by default, a negative one refused. */
  p.clip_plane_count = 0;
  CHECK(p.march_reach == 6.0, "default march reach %g", p.march_reach);
  p.march_reach = -1.0;
  CHECK(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, f, W * H * 4) ==
            CYLVOL_STATUS_INVALID_ARGUMENT,
        "a negative march reach");
  /* The error bound: off (0) by default, with no error-bounded work; at 2/255 the picture is
     within a few 1/255 of the fixed step's, samples are refined, and NaN is refused. */
  p.march_reach = 6.0;
  CHECK(p.max_error == 0.0, "default max error %g", p.max_error);
  CHECK(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, f, W * H * 4) ==
            CYLVOL_STATUS_OK,
        "fixed-step render: %s", cylvol_last_error());
  CHECK(cylvol_volume_render_stats(v, &stats) == CYLVOL_STATUS_OK && stats.refined_samples == 0 &&
            stats.slopes == 0 && stats.integrated_stretches == 0,
        "the fixed step refined %llu samples", (unsigned long long)stats.refined_samples);
  p.max_error = 2.0;
  CHECK(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, bounded,
                      W * H * 4) == CYLVOL_STATUS_OK,
        "error-bounded render: %s", cylvol_last_error());
  CHECK(cylvol_volume_render_stats(v, &stats) == CYLVOL_STATUS_OK && stats.refined_samples > 0 &&
            stats.integrated_stretches > 0,
        "an error-bounded render refined %llu samples", (unsigned long long)stats.refined_samples);
  for (k = 0; k < W * H * 4; ++k) {
    double d = fabs((double)bounded[k] - (double)f[k]) * 255.0;
    if (d > largest) largest = d;
  }
  CHECK(largest < 8.0, "the bounded picture is %g/255 from the fixed step's", largest);
  p.max_error = NAN;
  CHECK(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, f, W * H * 4) ==
                CYLVOL_STATUS_INVALID_ARGUMENT &&
            strstr(cylvol_last_error(), "params->max_error = NaN") != NULL,
        "a NaN max error: %s", cylvol_last_error());
  cylvol_volume_free(v);
  cylvol_mesh_free(mesh);
  arrays_free(&a);
}

/* ---- errors ------------------------------------------------------------------------------ */

static void test_errors(void) {
  Arrays a, bad;
  CylvolMesh *mesh = NULL, *bare = NULL;
  CylvolVolume *v = NULL, *vbare = NULL;
  CylvolCamera camera = down_z();
  CylvolTransfer t = constant_transfer();
  CylvolRenderParams p;
  CylvolBuildParams bp;
  float pixels[4 * 4 * 4], depth[16];
  double range[2], bounds[6];
  double *scalars;
  size_t i;
  const char *mnew = "cylvol_mesh_new", *mset = "cylvol_mesh_set_scalars";
  const char *vnew = "cylvol_volume_new", *rend = "cylvol_render";

  cube(&a, 2);
  scalars = calloc(a.n_points, sizeof(double));
  for (i = 0; i < a.n_points; ++i) scalars[i] = (double)i;

  /* mesh_new */
  mesh = (CylvolMesh *)&a; /* must be reset to NULL on failure */
  expect_status(cylvol_mesh_new(NULL, CYLVOL_VALUE_F64, a.n_points, a.offsets, a.connectivity,
                                CYLVOL_INDEX_I64, a.connectivity_len, a.types, a.n_cells, &mesh),
                CYLVOL_STATUS_NULL_POINTER, mnew, "NULL points");
  CHECK(mesh == NULL, "*out is NULL after a failure");
  expect_status(cylvol_mesh_new(a.points, CYLVOL_VALUE_F64, a.n_points, a.offsets, a.connectivity,
                                CYLVOL_INDEX_I64, a.connectivity_len, a.types, a.n_cells, NULL),
                CYLVOL_STATUS_NULL_POINTER, mnew, "NULL out");
  expect_status(cylvol_mesh_new(a.points, (CylvolValueType)7, a.n_points, a.offsets,
                                a.connectivity, CYLVOL_INDEX_I64, a.connectivity_len, a.types,
                                a.n_cells, &mesh),
                CYLVOL_STATUS_INVALID_ARGUMENT, mnew, "bad value type");
  expect_status(cylvol_mesh_new(a.points, CYLVOL_VALUE_F64, a.n_points, a.offsets, a.connectivity,
                                (CylvolIndexType)-3, a.connectivity_len, a.types, a.n_cells,
                                &mesh),
                CYLVOL_STATUS_INVALID_ARGUMENT, mnew, "bad index type");
  a.points[4] = NAN;
  expect_status(mesh_new(&a, &mesh), CYLVOL_STATUS_INVALID_ARGUMENT, mnew, "NaN point");
  a.points[4] = 0.0;
  a.connectivity[9] = 1000;
  expect_status(mesh_new(&a, &mesh), CYLVOL_STATUS_OUT_OF_RANGE, mnew, "point id 1000");
  a.connectivity[9] = -1;
  expect_status(mesh_new(&a, &mesh), CYLVOL_STATUS_OUT_OF_RANGE, mnew, "point id -1");
  a.connectivity[9] = 1;
  expect_status(cylvol_mesh_new(a.points, CYLVOL_VALUE_F64, a.n_points, a.offsets, a.connectivity,
                                CYLVOL_INDEX_I64, a.connectivity_len - 1, a.types, a.n_cells,
                                &mesh),
                CYLVOL_STATUS_LENGTH_MISMATCH, mnew, "connectivity_len");
  a.types[3] = 5;
  expect_status(mesh_new(&a, &mesh), CYLVOL_STATUS_UNSUPPORTED_CELL, mnew, "triangle");
  CHECK(strstr(cylvol_last_error(), "triangle") != NULL, "names the type: %s",
        cylvol_last_error());
  a.types[3] = 12;
  expect_status(cylvol_mesh_new(a.points, CYLVOL_VALUE_F64, 0, a.offsets, a.connectivity,
                                CYLVOL_INDEX_I64, 0, a.types, 0, &mesh),
                CYLVOL_STATUS_INVALID_MESH, mnew, "empty mesh");
  cube(&bad, 1);
  for (i = 0; i < 4; ++i) { /* swap top and bottom: inverted */
    int64_t tmp = bad.connectivity[i];
    bad.connectivity[i] = bad.connectivity[i + 4];
    bad.connectivity[i + 4] = tmp;
  }
  expect_status(mesh_new(&bad, &mesh), CYLVOL_STATUS_INVALID_MESH, mnew, "inverted cell");
  arrays_free(&bad);

  /* set_scalars, counts, bounds, range */
  CHECK(mesh_new(&a, &bare) == CYLVOL_STATUS_OK, "mesh: %s", cylvol_last_error());
  expect_status(cylvol_mesh_scalar_range(bare, range), CYLVOL_STATUS_NO_SCALARS,
                "cylvol_mesh_scalar_range", "no scalars yet");
  expect_status(cylvol_mesh_set_scalars(NULL, "s", CYLVOL_POINT_DATA, scalars, CYLVOL_VALUE_F64,
                                        a.n_points, 1, 0),
                CYLVOL_STATUS_NULL_POINTER, mset, "NULL mesh");
  expect_status(cylvol_mesh_set_scalars(bare, "s", CYLVOL_POINT_DATA, NULL, CYLVOL_VALUE_F64,
                                        a.n_points, 1, 0),
                CYLVOL_STATUS_NULL_POINTER, mset, "NULL values");
  expect_status(cylvol_mesh_set_scalars(bare, "s", (CylvolAssociation)2, scalars,
                                        CYLVOL_VALUE_F64, a.n_points, 1, 0),
                CYLVOL_STATUS_INVALID_ARGUMENT, mset, "bad association");
  expect_status(cylvol_mesh_set_scalars(bare, "s", CYLVOL_POINT_DATA, scalars, CYLVOL_VALUE_F64,
                                        a.n_points - 1, 1, 0),
                CYLVOL_STATUS_LENGTH_MISMATCH, mset, "n_tuples");
  expect_status(cylvol_mesh_set_scalars(bare, "s", CYLVOL_CELL_DATA, scalars, CYLVOL_VALUE_F64,
                                        a.n_points, 1, 0),
                CYLVOL_STATUS_LENGTH_MISMATCH, mset, "cell data of point length");
  expect_status(cylvol_mesh_set_scalars(bare, "s", CYLVOL_POINT_DATA, scalars, CYLVOL_VALUE_F64,
                                        a.n_points, 1, 1),
                CYLVOL_STATUS_OUT_OF_RANGE, mset, "component 1 of 1");
  expect_status(cylvol_mesh_set_scalars(bare, "s", CYLVOL_POINT_DATA, scalars, CYLVOL_VALUE_F64,
                                        a.n_points, 1, -2),
                CYLVOL_STATUS_OUT_OF_RANGE, mset, "component -2");
  expect_status(cylvol_mesh_set_scalars(bare, "s", CYLVOL_POINT_DATA, scalars, CYLVOL_VALUE_F64,
                                        a.n_points, 0, 0),
                CYLVOL_STATUS_INVALID_ARGUMENT, mset, "zero components");
  scalars[3] = NAN;
  expect_status(cylvol_mesh_set_scalars(bare, "s", CYLVOL_POINT_DATA, scalars, CYLVOL_VALUE_F64,
                                        a.n_points, 1, 0),
                CYLVOL_STATUS_INVALID_ARGUMENT, mset, "NaN scalar");
  scalars[3] = 3.0;
  expect_status(cylvol_mesh_counts(bare, NULL, NULL), CYLVOL_STATUS_NULL_POINTER,
                "cylvol_mesh_counts", "NULL counts");
  expect_status(cylvol_mesh_bounds(NULL, bounds), CYLVOL_STATUS_NULL_POINTER,
                "cylvol_mesh_bounds", "NULL mesh");

  /* volume_new */
  cylvol_build_params_default(&bp);
  bp.structure = (CylvolStructure)9;
  expect_status(cylvol_volume_new(bare, &bp, &v), CYLVOL_STATUS_INVALID_ARGUMENT, vnew,
                "bad structure");
  cylvol_build_params_default(&bp);
  bp.preset = 42;
  expect_status(cylvol_volume_new(bare, &bp, &v), CYLVOL_STATUS_INVALID_ARGUMENT, vnew,
                "bad preset");
  cylvol_build_params_default(&bp);
  bp.axis_auto = 0;
  bp.axis_direction[0] = bp.axis_direction[1] = bp.axis_direction[2] = 0.0;
  expect_status(cylvol_volume_new(bare, &bp, &v), CYLVOL_STATUS_INVALID_ARGUMENT, vnew,
                "zero axis");
  expect_status(cylvol_volume_new(NULL, NULL, &v), CYLVOL_STATUS_NULL_POINTER, vnew, "NULL mesh");
  CHECK(v == NULL, "no volume after failures");

  /* render */
  vbare = volume_new(bare, CYLVOL_STRUCTURE_CARTESIAN_BVH);
  cylvol_render_params_default(&p);
  p.width = 4;
  p.height = 4;
  expect_status(cylvol_render(vbare, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels,
                              64),
                CYLVOL_STATUS_NO_SCALARS, rend, "no scalars");
  CHECK(strlen(cylvol_volume_last_error(vbare)) > 0, "the volume keeps its last error");
  CHECK(cylvol_volume_set_scalars(vbare, NULL, CYLVOL_POINT_DATA, scalars, CYLVOL_VALUE_F64,
                                  a.n_points, 1, 0) == CYLVOL_STATUS_OK,
        "volume_set_scalars: %s", cylvol_last_error());
  expect_status(cylvol_volume_set_scalars(vbare, NULL, CYLVOL_CELL_DATA, scalars,
                                          CYLVOL_VALUE_F64, a.n_points, 1, 0),
                CYLVOL_STATUS_LENGTH_MISMATCH, "cylvol_volume_set_scalars", "volume n_tuples");
  v = vbare;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_OK, rend, "good render");
  expect_status(cylvol_render(NULL, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels,
                              64),
                CYLVOL_STATUS_NULL_POINTER, rend, "NULL volume");
  expect_status(cylvol_render(v, NULL, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_NULL_POINTER, rend, "NULL camera");
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, NULL, 64),
                CYLVOL_STATUS_NULL_POINTER, rend, "NULL pixels");
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 63),
                CYLVOL_STATUS_LENGTH_MISMATCH, rend, "pixels_len");
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, (CylvolPixelFormat)5, pixels, 64),
                CYLVOL_STATUS_INVALID_ARGUMENT, rend, "bad format");
  p.width = 0;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 0),
                CYLVOL_STATUS_INVALID_ARGUMENT, rend, "zero width");
  p.width = 4;
  p.path = (CylvolPath)3;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_INVALID_ARGUMENT, rend, "bad path");
  p.path = CYLVOL_PATH_PAPER;
  p.step = NAN;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_INVALID_ARGUMENT, rend, "NaN step");
  p.step = 0.0;
  camera.eye[2] = NAN;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_INVALID_ARGUMENT, rend, "NaN camera");
  camera = down_z();
  camera.mode = (CylvolCameraMode)4;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_INVALID_ARGUMENT, rend, "bad camera mode");
  camera = down_z();
  constant_opacity[1] = NAN;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_INVALID_ARGUMENT, rend, "NaN opacity");
  constant_opacity[1] = 0.3f;
  t.n_color = 1;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_INVALID_ARGUMENT, rend, "one colour");
  t.n_color = 2;
  t.opacity = NULL;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_NULL_POINTER, rend, "NULL opacity table");
  t.opacity = constant_opacity;
  for (i = 0; i < 16; ++i) depth[i] = NAN;
  expect_status(cylvol_render(v, &camera, &t, &p, depth, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_INVALID_ARGUMENT, rend, "NaN depth");
  CHECK(strstr(cylvol_volume_last_error(v), "depth_in") != NULL, "volume detail: %s",
        cylvol_volume_last_error(v));
  p.interpolation = (CylvolInterpolation)2;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_INVALID_ARGUMENT, rend, "bad interpolation");
  p.interpolation = CYLVOL_INTERPOLATION_NEAREST;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_OK, rend, "nearest");
  {
    static const float gradient[2] = {0.0f, 2.0f};
    t.gradient_opacity = gradient;
    t.n_gradient_opacity = 2;
    t.gradient_range[0] = 0.0;
    t.gradient_range[1] = 1.0;
    expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels,
                                64),
                  CYLVOL_STATUS_INVALID_ARGUMENT, rend, "gradient opacity above 1");
    t.gradient_opacity = NULL;
  }
  p.interpolation = CYLVOL_INTERPOLATION_LINEAR;
  expect_status(cylvol_render(v, &camera, &t, &p, NULL, NULL, CYLVOL_PIXELS_RGBA_F32, pixels, 64),
                CYLVOL_STATUS_OK, rend, "good render again");
  expect_status(cylvol_volume_render_stats(v, NULL), CYLVOL_STATUS_NULL_POINTER,
                "cylvol_volume_render_stats", "NULL stats");

  /* messages */
  for (i = 0; i <= 8; ++i) {
    const char *m = cylvol_status_message((CylvolStatus)i);
    CHECK(m != NULL && strlen(m) > 0 && strcmp(m, "unknown status") != 0, "message %zu", i);
  }
  CHECK(strcmp(cylvol_status_message((CylvolStatus)99), "unknown status") == 0, "unknown");
  CHECK(strlen(cylvol_version()) > 0, "version");

  cylvol_volume_free(vbare);
  cylvol_mesh_free(bare);
  cylvol_mesh_free(NULL);
  cylvol_volume_free(NULL);
  free(scalars);
  arrays_free(&a);
}

int main(void) {
  printf("cylvol %s\n", cylvol_version());
  test_beer_lambert_and_formats();
  test_mixed_cells();
  test_errors();
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
