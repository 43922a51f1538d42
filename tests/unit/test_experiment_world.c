/*
 * The generated navigation worlds and what the observer sees of them: the
 * path lies inside the field, its vertices are sandy and the rock is not, the
 * canyon walls rise beside the floor, the same seed gives the same mesh, and
 * asp_experiment_see_path steers toward where the sandy pixels are.
 */
#include "amgsplat/amgsplat.h"
#include "amgsplat/experiment.h"
#include "harness.h"

static int sandy(const uint8_t *c)
{
    return c[0] > 60 && (float)(c[0] - c[2]) > 0.22f * (float)c[0];
}

static void check_world(const asp_experiment_scene *s)
{
    asp_experiment_world w, v;
    CHECK_OK(asp_experiment_world_generate(s, NULL, &w, NULL), NULL);
    CHECK_OK(asp_experiment_world_generate(s, NULL, &v, NULL), NULL);
    if (!w.mesh || !v.mesh)
        return;
    CHECK(w.mesh->vertex_count == (size_t)s->grid * s->grid && w.path_count >= 16);
    CHECK(memcmp(w.mesh->positions, v.mesh->positions, 12 * w.mesh->vertex_count) == 0);
    CHECK(memcmp(w.mesh->colors, v.mesh->colors, 4 * w.mesh->vertex_count) == 0);
    for (size_t i = 0; i < w.path_count; i++) {
        CHECK(fabsf(w.path[3 * i]) < 0.5f * s->size && fabsf(w.path[3 * i + 2]) < 0.5f * s->size);
        CHECK_NEAR(w.path[3 * i + 1], asp_experiment_world_height(&w, w.path[3 * i], w.path[3 * i + 2]), 1e-4);
    }
    // vertex colour: sandy exactly within half_width of the centre line
    size_t wrong = 0, on = 0;
    double rock = 0.0, floor = 0.0;
    size_t nrock = 0, nfloor = 0;
    for (size_t i = 0; i < w.mesh->vertex_count; i++) {
        const float *p = &w.mesh->positions[3 * i];
        float d = asp_experiment_path_nearest(w.path, w.path_count, p[0], p[2], NULL, NULL);
        int in = d < s->half_width;
        on += (size_t)in;
        wrong += (size_t)(in != sandy(&w.mesh->colors[4 * i]));
        if (d > 3.0f * s->half_width) {
            rock += p[1];
            nrock++;
        } else if (in) {
            floor += p[1];
            nfloor++;
        }
    }
    CHECK(on > 10 && wrong == 0);
    // rocks and canyon walls stand above the path
    CHECK_MSG(rock / (double)nrock > floor / (double)nfloor + 0.3 * s->relief, "rock %g floor %g",
              rock / (double)nrock, floor / (double)nfloor);
    float along = -1.0f, dir[2];
    float d = asp_experiment_path_nearest(w.path, w.path_count, w.path[0], w.path[2], &along, dir);
    CHECK_NEAR(d, 0.0, 1e-5);
    CHECK_NEAR(along, 0.0, 1e-6);
    CHECK(dir[1] > 0.0f); // the path runs toward +z
    size_t last = w.path_count - 1;
    asp_experiment_path_nearest(w.path, w.path_count, w.path[3 * last], w.path[3 * last + 2], &along, NULL);
    CHECK_NEAR(along, 1.0, 1e-6);
    asp_experiment_world_release(&w);
    asp_experiment_world_release(&v);
}

static void test_worlds(void)
{
    asp_experiment_scenes sc;
    asp_experiment_scenes_default(&sc);
    for (int t = ASP_EXPERIMENT_LOWSPEED; t <= ASP_EXPERIMENT_HIGHSPEED; t++) {
        asp_experiment_scene s = sc.tests[t];
        s.grid = 65;
        check_world(&s);
    }
    asp_experiment_scene bad = sc.tests[ASP_EXPERIMENT_LOWSPEED];
    bad.grid = 4;
    asp_experiment_world w;
    asp_error err = {0};
    CHECK(asp_experiment_world_generate(&bad, NULL, &w, &err) == ASP_EINVAL && w.mesh == NULL);
    CHECK(strstr(err.msg, "grid 8..2048") != NULL);
}

static void fill(asp_image *img, uint32_t x0, uint32_t x1, const uint8_t c[4])
{
    for (uint32_t y = 0; y < img->height; y++)
        for (uint32_t x = x0; x < x1; x++)
            memcpy(&img->pixels[4 * ((size_t)y * img->width + x)], c, 4);
}

static void test_see_path(void)
{
    static const uint8_t sky[4] = {150, 190, 230, 255}, rock[4] = {120, 117, 113, 255},
                         sand[4] = {222, 190, 128, 255}, shaded_sand[4] = {90, 77, 52, 255};
    asp_image img = {0};
    CHECK_OK(asp_image_init(&img, 160, 120, NULL), NULL);
    float frac = -1.0f, steer = 9.0f;
    asp_image_fill(&img, sky);
    asp_experiment_see_path(&img, 0.5f, 1.0f, &frac, &steer);
    CHECK(frac == 0.0f && steer == 0.0f); // a blank frame shows no path
    asp_image_fill(&img, rock);
    fill(&img, 20, 40, sand); // the path on the left
    asp_experiment_see_path(&img, 0.5f, 1.0f, &frac, &steer);
    CHECK_NEAR(frac, 20.0 / 160.0, 1e-6);
    CHECK_NEAR(steer, -0.625, 1e-3); // columns 20..39: centre 30 of 160 -> -0.625
    asp_image_fill(&img, rock);
    fill(&img, 120, 160, shaded_sand); // shading keeps the hue: still the path, now on the right
    asp_experiment_see_path(&img, 0.5f, 1.0f, &frac, &steer);
    CHECK(frac > 0.2f && steer > 0.7f);
    asp_image_release(&img);
}

TEST_MAIN(TEST_CASE(test_worlds), TEST_CASE(test_see_path))
