/*
 * Mesh renderer on a real headless GL 4.5 context (issue 14): a unit quad
 * facing the camera with a 2x2 texture shows each texel's sRGB colour exactly
 * under the headlight (sRGB decode before lighting, v = 0 at the image
 * bottom), the Lambert term of the point renderers, trilinear mipmaps averaged
 * in linear light, material and vertex colours, per-triangle materials, the
 * frame offset, the renderer table row and bad input.
 */
#include <math.h>
#include <string.h>

#include "amgsplat/render.h"
#include "gl_harness.h"
#include "harness.h"

static asp_error *ep(asp_error *e)
{
    return e;
}

static double srgb_to_linear(double c)
{
    c /= 255.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static double linear_to_srgb(double l)
{
    double c = l <= 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1.0 / 2.4) - 0.055;
    return 255.0 * c;
}

/* The quad [-1, 1]^2 at z = 0 facing +z, UVs 0..1 over it, two triangles. */
static const float quad_pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
static const float quad_nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
static const float quad_uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
static const uint32_t quad_tri[6] = {0, 1, 2, 0, 2, 3};

static asp_render_mesh quad(void)
{
    asp_render_mesh m;
    memset(&m, 0, sizeof m);
    m.vertex_count = 4;
    m.triangle_count = 2;
    m.positions = quad_pos;
    m.normals = quad_nrm;
    m.triangles = quad_tri;
    return m;
}

/* From +z, the quad's bounding sphere filling a 128 x 128 view. */
static void front_camera(asp_camera *cam)
{
    asp_camera_init(cam);
    asp_camera_fit(cam, (const float[3]){0, 0, 0}, sqrtf(2.0f), 1.0f);
}

static const uint8_t *pixel_at(const asp_image *img, const asp_camera *cam, float x, float y)
{
    float p[3];
    asp_camera_project(cam, (const float[3]){x, y, 0}, img->width, img->height, p);
    uint32_t i = (uint32_t)p[0], j = (uint32_t)p[1];
    return img->pixels + 4 * ((size_t)j * img->width + i);
}

static int near_rgb(const uint8_t *p, double r, double g, double b, double tol)
{
    return fabs(p[0] - r) <= tol && fabs(p[1] - g) <= tol && fabs(p[2] - b) <= tol;
}

static int draw(const asp_render_mesh *m, const asp_mesh_renderer_desc *d, const asp_camera *cam,
                const asp_render_desc *rd, asp_image *img)
{
    asp_error err = {0, ""};
    asp_renderer *r = NULL;
    int rc = asp_mesh_renderer_create(gl, m, d, &r, &err);
    CHECK_OK(rc, ep(&err));
    if (rc)
        return rc;
    CHECK(strcmp(asp_renderer_name(r), "mesh") == 0);
    CHECK(asp_renderer_count(r) == m->triangle_count);
    rc = asp_render_to_image(gl, r, cam, rd, img, &err);
    CHECK_OK(rc, ep(&err));
    asp_renderer_destroy(r);
    return rc;
}

/*
 * 2x2 colours, rows top first: top row (200, 30, 30) (30, 200, 30), bottom
 * row (128, 64, 200) (250, 250, 10), each a 2x2 block of a 4x4 texture so the
 * linear filter is flat around each quarter's centre (a 2x2 texture would
 * blend neighbours there by the sub-pixel position). The quad's bottom-left
 * quarter shows the image's bottom-left colour. An sRGB texture decoded as
 * linear would show (128, 64, 200) as about (188, 137, 228).
 */
static void test_textured_quad(void)
{
    if (!gl)
        return;
    static const uint8_t colours[4][4] = {{200, 30, 30, 255}, {30, 200, 30, 255}, {128, 64, 200, 255},
                                          {250, 250, 10, 255}};
    static uint8_t texels[4 * 16];
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++)
            memcpy(texels + 4 * (4 * y + x), colours[2 * (y / 2) + x / 2], 4);
    asp_image tex = {4, 4, texels};
    asp_render_material mat = {{1, 1, 1, 1}, &tex};
    asp_render_mesh m = quad();
    m.uvs = quad_uv;
    m.material_count = 1;
    m.materials = &mat;
    asp_camera cam;
    front_camera(&cam);
    asp_image img = {0, 0, NULL};
    if (draw(&m, NULL, &cam, &(asp_render_desc){.width = 128, .height = 128}, &img))
        return;
    const uint8_t *bl = pixel_at(&img, &cam, -0.5f, -0.5f), *br = pixel_at(&img, &cam, 0.5f, -0.5f);
    const uint8_t *tl = pixel_at(&img, &cam, -0.5f, 0.5f), *tr = pixel_at(&img, &cam, 0.5f, 0.5f);
    CHECK_MSG(near_rgb(bl, 128, 64, 200, 2), "bottom left %d %d %d", bl[0], bl[1], bl[2]);
    CHECK_MSG(near_rgb(br, 250, 250, 10, 2), "bottom right %d %d %d", br[0], br[1], br[2]);
    CHECK_MSG(near_rgb(tl, 200, 30, 30, 2), "top left %d %d %d", tl[0], tl[1], tl[2]);
    CHECK_MSG(near_rgb(tr, 30, 200, 30, 2), "top right %d %d %d", tr[0], tr[1], tr[2]);
    // background outside the quad (the corners of the view)
    CHECK(img.pixels[3] == 0);
    asp_image_release(&img);

    // light 60 degrees aside: colour * (0.25 + 0.75 cos 60) in linear light, as the discs
    if (draw(&m, NULL, &cam, &(asp_render_desc){.width = 128, .height = 128, .light_azimuth = 60}, &img))
        return;
    bl = pixel_at(&img, &cam, -0.5f, -0.5f);
    double s = 0.25 + 0.75 * 0.5;
    double er = linear_to_srgb(srgb_to_linear(128) * s), eg = linear_to_srgb(srgb_to_linear(64) * s),
           eb = linear_to_srgb(srgb_to_linear(200) * s);
    CHECK_MSG(near_rgb(bl, er, eg, eb, 2), "lit %d %d %d, expected %.1f %.1f %.1f", bl[0], bl[1], bl[2], er, eg, eb);
    asp_image_release(&img);

    // unlit: the texel as it is, whatever the light
    if (draw(&m, NULL, &cam,
             &(asp_render_desc){.width = 128, .height = 128, .light_azimuth = 80, .flags = ASP_RENDER_UNLIT}, &img))
        return;
    bl = pixel_at(&img, &cam, -0.5f, -0.5f);
    CHECK_MSG(near_rgb(bl, 128, 64, 200, 2), "unlit %d %d %d", bl[0], bl[1], bl[2]);
    asp_image_release(&img);
}

/*
 * A 64x64 checkerboard of black and white texels seen from far away (the quad
 * 8 pixels wide): trilinear mipmaps average it to grey 0.5 in linear light,
 * sRGB 188; averaging the code values would give 128, no mipmaps would alias.
 */
static void test_mipmaps_linear_light(void)
{
    if (!gl)
        return;
    enum { N = 64 };
    static uint8_t texels[4 * N * N];
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            uint8_t v = (x + y) % 2 ? 255 : 0;
            memset(texels + 4 * (y * N + x), v, 3);
            texels[4 * (y * N + x) + 3] = 255;
        }
    asp_image tex = {N, N, texels};
    asp_render_material mat = {{1, 1, 1, 1}, &tex};
    asp_render_mesh m = quad();
    m.uvs = quad_uv;
    m.material_count = 1;
    m.materials = &mat;
    asp_camera cam;
    front_camera(&cam);
    // the quad's 2 units over 128 px at this distance are about 90 px: 11 times further gives 8
    cam.distance *= 11.0f;
    asp_camera_clip_to_sphere(&cam, cam.target, sqrtf(2.0f));
    asp_image img = {0, 0, NULL};
    if (draw(&m, NULL, &cam, &(asp_render_desc){.width = 128, .height = 128}, &img))
        return;
    const uint8_t *c = img.pixels + 4 * (64 * 128 + 64);
    CHECK_MSG(near_rgb(c, 188, 188, 188, 6), "far checkerboard %d %d %d (expected 188)", c[0], c[1], c[2]);
    asp_image_release(&img);
}

/* Two materials, one per triangle; then vertex colours, which replace material colours (the sampler's rule). */
static void test_material_and_vertex_colours(void)
{
    if (!gl)
        return;
    asp_render_material mats[2] = {{{1, 0, 0, 1}, NULL}, {{0.5f, 0.5f, 1, 1}, NULL}};
    static const uint32_t ids[2] = {0, 1};
    asp_render_mesh m = quad();
    m.material_ids = ids;
    m.material_count = 2;
    m.materials = mats;
    asp_camera cam;
    front_camera(&cam);
    asp_image img = {0, 0, NULL};
    if (draw(&m, NULL, &cam, &(asp_render_desc){.width = 128, .height = 128}, &img))
        return;
    // triangle 0 (0, 1, 2) is below the diagonal y = x, triangle 1 above it
    const uint8_t *lower = pixel_at(&img, &cam, 0.5f, -0.5f), *upper = pixel_at(&img, &cam, -0.5f, 0.5f);
    CHECK_MSG(near_rgb(lower, 255, 0, 0, 1), "material 0 %d %d %d", lower[0], lower[1], lower[2]);
    CHECK_MSG(near_rgb(upper, 127.5, 127.5, 255, 1), "material 1 %d %d %d", upper[0], upper[1], upper[2]);
    asp_image_release(&img);

    // one colour per vertex: the quad's centre interpolates in sRGB like the sampler (diagonal: v0 and v2)
    static const uint8_t colors[16] = {0, 100, 0, 255, 0, 0, 0, 255, 200, 100, 0, 255, 0, 0, 0, 255};
    m.colors = colors;
    if (draw(&m, NULL, &cam, &(asp_render_desc){.width = 128, .height = 128}, &img))
        return;
    const uint8_t *c = pixel_at(&img, &cam, 0.0f, 0.0f), *v2 = pixel_at(&img, &cam, 0.98f, 0.98f);
    CHECK_MSG(near_rgb(c, 100, 100, 0, 3), "centre %d %d %d", c[0], c[1], c[2]);
    CHECK_MSG(near_rgb(v2, 196, 100, 0, 5), "near vertex 2 %d %d %d", v2[0], v2[1], v2[2]);
    asp_image_release(&img);

    // no materials at all: the point renderers' light grey
    asp_render_mesh plain = quad();
    if (draw(&plain, NULL, &cam, &(asp_render_desc){.width = 64, .height = 64}, &img))
        return;
    c = img.pixels + 4 * (32 * 64 + 32);
    CHECK_MSG(near_rgb(c, 200, 200, 200, 1), "default %d %d %d", c[0], c[1], c[2]);
    asp_image_release(&img);
}

/*
 * Frames and normals: a mesh at origin 1000 drawn in the frame of 1000 is
 * the mesh at 0 drawn at 0; flat shading ignores tilted vertex normals (the
 * face faces the light), smooth shading follows them.
 */
static void test_frame_and_normals(void)
{
    if (!gl)
        return;
    asp_camera cam;
    front_camera(&cam);
    asp_render_mesh m = quad();
    asp_image a = {0, 0, NULL}, b = {0, 0, NULL};
    if (draw(&m, NULL, &cam, &(asp_render_desc){.width = 64, .height = 64}, &a))
        return;
    m.origin[0] = 1000.0;
    m.origin[2] = -3000.0;
    asp_mesh_renderer_desc d = {.origin = {1000.0, 0.0, -3000.0}};
    if (draw(&m, &d, &cam, &(asp_render_desc){.width = 64, .height = 64}, &b) == 0) {
        CHECK(memcmp(a.pixels, b.pixels, 4 * 64 * 64) == 0);
        asp_image_release(&b);
    }
    // a frame half a unit to the right draws the quad half a unit to the left
    d.origin[0] = 1000.5;
    if (draw(&m, &d, &cam, &(asp_render_desc){.width = 64, .height = 64}, &b) == 0) {
        CHECK(memcmp(a.pixels, b.pixels, 4 * 64 * 64) != 0);
        CHECK(pixel_at(&b, &cam, -1.3f, 0.0f)[3] == 255 && pixel_at(&a, &cam, -1.3f, 0.0f)[3] == 0);
        asp_image_release(&b);
    }
    asp_image_release(&a);

    // vertex normals tilted 60 degrees from the view: smooth is darker, flat is the full colour
    static const float tilted[12] = {0.8660254f, 0, 0.5f, 0.8660254f, 0, 0.5f, 0.8660254f, 0, 0.5f,
                                     0.8660254f, 0, 0.5f};
    asp_render_mesh t = quad();
    t.normals = tilted;
    if (draw(&t, NULL, &cam, &(asp_render_desc){.width = 64, .height = 64}, &a))
        return;
    double expect = linear_to_srgb(srgb_to_linear(200) * (0.25 + 0.75 * 0.5));
    const uint8_t *c = a.pixels + 4 * (32 * 64 + 32);
    CHECK_MSG(near_rgb(c, expect, expect, expect, 2), "smooth %d (expected %.1f)", c[0], expect);
    asp_image_release(&a);
    if (draw(&t, &(asp_mesh_renderer_desc){.flags = ASP_MESH_RENDER_FLAT}, &cam,
             &(asp_render_desc){.width = 64, .height = 64}, &a))
        return;
    c = a.pixels + 4 * (32 * 64 + 32);
    CHECK_MSG(near_rgb(c, 200, 200, 200, 1), "flat %d", c[0]);
    asp_image_release(&a);
}

/* The renderer table's "mesh" row draws a source's mesh and refuses sources without one. */
static void test_renderer_table(void)
{
    if (!gl)
        return;
    const asp_renderer_kind *k = NULL;
    asp_error err = {0, ""};
    CHECK_OK(asp_renderer_kind_find("mesh", ASP_RENDER_INPUT_MESH, &k, &err), ep(&err));
    if (!k)
        return;
    CHECK(strcmp(k->noun, "triangles") == 0 && !k->has_lod);
    CHECK(asp_renderer_kind_find("mesh", ASP_RENDER_INPUT_POINTS, &k, &err) == ASP_EINVAL);
    CHECK(asp_renderer_kind_find("disc", ASP_RENDER_INPUT_MESH, &k, &err) == ASP_EINVAL);
    CHECK_MSG(strstr(err.msg, "expected mesh") != NULL, "message '%s'", err.msg);
    CHECK_OK(asp_renderer_kind_find("mesh", 0, &k, &err), ep(&err));
    asp_renderer *r = NULL;
    CHECK(k->create(gl, &(asp_render_source){0}, NULL, NULL, &r, &err) == ASP_EUNSUPPORTED && r == NULL);
    asp_render_mesh m = quad();
    CHECK_OK(k->create(gl, &(asp_render_source){.mesh = &m}, NULL, NULL, &r, &err), ep(&err));
    CHECK(r && asp_renderer_count(r) == 2);
    asp_renderer_destroy(r);
}

static void test_bad_input(void)
{
    if (!gl)
        return;
    asp_error err = {0, ""};
    asp_renderer *r = NULL;
    asp_render_mesh m = quad();
    m.triangle_count = 0;
    CHECK(asp_mesh_renderer_create(gl, &m, NULL, &r, &err) == ASP_EDEGENERATE && r == NULL);
    static const uint32_t bad_tri[6] = {0, 1, 2, 0, 2, 4};
    m = quad();
    m.triangles = bad_tri;
    CHECK(asp_mesh_renderer_create(gl, &m, NULL, &r, &err) == ASP_EFORMAT && r == NULL);
    CHECK_MSG(strstr(err.msg, "triangle 1") != NULL, "message '%s'", err.msg);
    static const uint32_t bad_ids[2] = {0, 1};
    m = quad();
    m.material_ids = bad_ids; // one implicit material only
    CHECK(asp_mesh_renderer_create(gl, &m, NULL, &r, &err) == ASP_EFORMAT && r == NULL);
    CHECK_MSG(strstr(err.msg, "material 1") != NULL, "message '%s'", err.msg);
    float nan_pos[12];
    memcpy(nan_pos, quad_pos, sizeof nan_pos);
    nan_pos[7] = NAN;
    m = quad();
    m.positions = nan_pos;
    CHECK(asp_mesh_renderer_create(gl, &m, NULL, &r, &err) == ASP_EFORMAT && r == NULL);
    CHECK_MSG(strstr(err.msg, "vertex 2") != NULL, "message '%s'", err.msg);
}

TEST_MAIN(TEST_FIXTURE(setup), TEST_CASE(test_textured_quad), TEST_CASE(test_mipmaps_linear_light),
          TEST_CASE(test_material_and_vertex_colours), TEST_CASE(test_frame_and_normals),
          TEST_CASE(test_renderer_table), TEST_CASE(test_bad_input), TEST_FIXTURE(teardown))
