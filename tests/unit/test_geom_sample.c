/*
 * Mesh sampling: even density, hole-free discs, texture/vertex/material
 * colours, normal interpolation, exact voxel cell counts, determinism and
 * degenerate input, on meshes built in code.
 */
#include "amgsplat/amgsplat.h"
#include "harness.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* m x m grid of quads over [0,1]^2 at z = 0, two triangles each, uvs = xy. */
static asp_mesh *plane_mesh(int m)
{
    asp_mesh *mesh = NULL;
    size_t nv = (size_t)(m + 1) * (m + 1), nt = 2 * (size_t)m * m;
    if (asp_mesh_create(nv, nt, ASP_MESH_UVS, NULL, &mesh, NULL))
        return NULL;
    for (int j = 0; j <= m; j++)
        for (int i = 0; i <= m; i++) {
            size_t v = (size_t)j * (m + 1) + i;
            mesh->positions[3 * v] = (float)i / m;
            mesh->positions[3 * v + 1] = (float)j / m;
            mesh->normals[3 * v + 2] = 1.0f;
            mesh->uvs[2 * v] = (float)i / m;
            mesh->uvs[2 * v + 1] = (float)j / m;
        }
    size_t t = 0;
    for (int j = 0; j < m; j++)
        for (int i = 0; i < m; i++) {
            uint32_t a = (uint32_t)(j * (m + 1) + i), b = a + 1, c = a + (uint32_t)m + 1, d = c + 1;
            uint32_t tri[6] = {a, b, d, a, d, c};
            memcpy(mesh->triangles + 3 * t, tri, sizeof tri);
            t += 2;
        }
    return mesh;
}

/* Icosphere-like UV sphere: rings x segments, poles shared. */
static asp_mesh *sphere_mesh(int rings, int segs)
{
    asp_mesh *mesh = NULL;
    size_t nv = 2 + (size_t)(rings - 1) * segs, nt = 2 * (size_t)segs * (rings - 1);
    if (asp_mesh_create(nv, nt, 0, NULL, &mesh, NULL))
        return NULL;
    float *p = mesh->positions;
    p[2] = 1.0f;
    p[3 * (nv - 1) + 2] = -1.0f;
    for (int r = 1; r < rings; r++)
        for (int s = 0; s < segs; s++) {
            double th = M_PI * r / rings, ph = 2 * M_PI * s / segs;
            size_t v = 1 + (size_t)(r - 1) * segs + s;
            p[3 * v] = (float)(sin(th) * cos(ph)), p[3 * v + 1] = (float)(sin(th) * sin(ph)), p[3 * v + 2] = (float)cos(th);
        }
    uint32_t *t = mesh->triangles;
    for (int s = 0; s < segs; s++) {
        uint32_t a = 1 + (uint32_t)s, b = 1 + (uint32_t)((s + 1) % segs);
        *t++ = 0, *t++ = a, *t++ = b;
        uint32_t c = (uint32_t)(1 + (rings - 2) * segs + s), d = (uint32_t)(1 + (rings - 2) * segs + (s + 1) % segs);
        *t++ = (uint32_t)nv - 1, *t++ = d, *t++ = c;
    }
    for (int r = 1; r < rings - 1; r++)
        for (int s = 0; s < segs; s++) {
            uint32_t a = (uint32_t)(1 + (r - 1) * segs + s), b = (uint32_t)(1 + (r - 1) * segs + (s + 1) % segs);
            uint32_t c = a + (uint32_t)segs, d = b + (uint32_t)segs;
            *t++ = a, *t++ = c, *t++ = d;
            *t++ = a, *t++ = d, *t++ = b;
        }
    asp_mesh_compute_normals(mesh, NULL);
    return mesh;
}

static uint64_t lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return *s >> 11;
}

static double urand(uint64_t *s)
{
    return (double)lcg(s) / 9007199254740992.0;
}

static void test_area_density_and_cover(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_mesh *mesh = plane_mesh(10);
    asp_cloud *c = NULL;
    asp_sample_stats st;
    CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.points = 100000, .seed = 1}, NULL, &c, &st, err), err);
    if (!c) {
        asp_mesh_destroy(mesh);
        return;
    }
    CHECK(c->count == 100000 && st.points == 100000);
    CHECK_NEAR(st.area, 1.0, 1e-9);
    CHECK(c->colors == NULL); /* no colour source: no colours */
    size_t cell[8][8] = {{0}};
    int inside = 1;
    for (size_t i = 0; i < c->count; i++) {
        float x = c->positions[3 * i], y = c->positions[3 * i + 1];
        if (x < 0 || x > 1 || y < 0 || y > 1 || c->positions[3 * i + 2] != 0.0f || c->normals[3 * i + 2] != 1.0f)
            inside = 0;
        int cx = x >= 1 ? 7 : (int)(x * 8), cy = y >= 1 ? 7 : (int)(y * 8);
        cell[cy][cx]++;
    }
    CHECK(inside);
    double mean = 100000.0 / 64.0, worst = 0.0;
    for (int j = 0; j < 8; j++)
        for (int i = 0; i < 8; i++)
            worst = fmax(worst, fabs((double)cell[j][i] - mean) / mean);
    CHECK_MSG(worst <= 0.10, "worst cell deviates %.3f from the mean", worst);
    /* every interior point of the plane lies in some disc */
    asp_kdtree *tree = NULL;
    CHECK_OK(asp_kdtree_create(c->positions, c->count, 12, NULL, &tree, err), err);
    uint64_t s = 11;
    size_t miss = 0;
    for (int q = 0; tree && q < 50000; q++) {
        float p[3] = {(float)(0.01 + 0.98 * urand(&s)), (float)(0.01 + 0.98 * urand(&s)), 0.0f};
        asp_index idx[24];
        float d2[24];
        size_t got = asp_kdtree_knn(tree, p, 24, idx, d2), a;
        for (a = 0; a < got; a++)
            if (d2[a] <= c->radii[idx[a]] * c->radii[idx[a]])
                break;
        miss += a == got;
    }
    CHECK_MSG(miss == 0, "%zu of 50000 plane points are in no disc", miss);
    double spacing = sqrt(1.0 / 100000.0);
    CHECK_MSG(st.mean_radius > 0.5 * spacing && st.mean_radius < 1.2 * spacing, "mean radius %g", st.mean_radius);
    asp_kdtree_destroy(tree);
    asp_cloud_destroy(c);
    asp_mesh_destroy(mesh);
}

/* A 4x4 texture: left half red, right half blue. */
static void two_colour_texture(asp_image *img)
{
    asp_image_init(img, 4, 4, NULL);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++) {
            uint8_t *p = img->pixels + 4 * (y * 4 + x);
            p[0] = x < 2 ? 255 : 0, p[1] = 0, p[2] = x < 2 ? 0 : 255, p[3] = 255;
        }
}

static void test_texture_colours(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_mesh *mesh = plane_mesh(1);
    two_colour_texture(&mesh->materials[0].texture);
    asp_sample_method methods[] = {ASP_SAMPLE_AREA, ASP_SAMPLE_VOXEL};
    for (int mi = 0; mi < 2; mi++) {
        asp_cloud *c = NULL;
        asp_sample_desc d = {.method = methods[mi], .points = 20000, .grid = 64, .with_uvs = 1};
        CHECK_OK(asp_sample_mesh(mesh, &d, NULL, &c, NULL, err), err);
        if (!c)
            continue;
        CHECK(c->colors != NULL && c->uvs != NULL);
        size_t red = 0, blue = 0, bad = 0;
        for (size_t i = 0; c->colors && i < c->count; i++) {
            float x = c->positions[3 * i];
            const uint8_t *col = c->colors + 4 * i;
            /* texel centres at 1/8 .. 7/8: between 1/8 and 3/8 the bilinear lookup is pure red */
            if (x > 0.13f && x < 0.37f) {
                red++;
                bad += !(col[0] == 255 && col[1] == 0 && col[2] == 0);
            } else if (x > 0.63f && x < 0.87f) {
                blue++;
                bad += !(col[0] == 0 && col[1] == 0 && col[2] == 255);
            }
            CHECK_NEAR(c->uvs[2 * i], x, 1e-5);
        }
        CHECK(red > 0 && blue > 0);
        CHECK_MSG(bad == 0, "%s: %zu points with the wrong colour", asp_sample_method_name(methods[mi]), bad);
        asp_cloud_destroy(c);
    }
    asp_mesh_destroy(mesh);
}

static void test_vertex_and_material_colours(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_mesh *mesh = NULL;
    CHECK_OK(asp_mesh_create(3, 1, ASP_MESH_COLORS, NULL, &mesh, err), err);
    if (!mesh)
        return;
    float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    memcpy(mesh->positions, p, sizeof p);
    uint8_t col[12] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255};
    memcpy(mesh->colors, col, sizeof col);
    uint32_t tri[3] = {0, 1, 2};
    memcpy(mesh->triangles, tri, sizeof tri);
    for (int v = 0; v < 3; v++)
        mesh->normals[3 * v + 2] = 1.0f;
    asp_cloud *c = NULL;
    CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.points = 2000}, NULL, &c, NULL, err), err);
    int ok = c && c->colors;
    for (size_t i = 0; ok && i < c->count; i++) {
        /* barycentric weights are (1-x-y, x, y): red, green, blue */
        double x = c->positions[3 * i], y = c->positions[3 * i + 1];
        double e[3] = {255 * (1 - x - y), 255 * x, 255 * y};
        for (int k = 0; k < 3; k++)
            if (fabs(c->colors[4 * i + k] - e[k]) > 1.01)
                ok = 0;
    }
    CHECK(ok);
    asp_cloud_destroy(c);
    /* without vertex colours a file material colour paints every point */
    asp_free(&mesh->ctx, mesh->colors);
    mesh->colors = NULL;
    mesh->materials[0].has_color = 1;
    mesh->materials[0].diffuse[0] = 0.2f, mesh->materials[0].diffuse[1] = 0.4f, mesh->materials[0].diffuse[2] = 1.0f;
    c = NULL;
    CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_VERTICES}, NULL, &c, NULL, err), err);
    if (c) {
        CHECK(c->count == 3 && c->colors);
        for (size_t i = 0; c->colors && i < c->count; i++)
            CHECK(c->colors[4 * i] == 51 && c->colors[4 * i + 1] == 102 && c->colors[4 * i + 2] == 255);
    }
    asp_cloud_destroy(c);
    asp_mesh_destroy(mesh);
}

static void test_normal_interpolation(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_mesh *mesh = NULL;
    CHECK_OK(asp_mesh_create(3, 1, 0, NULL, &mesh, err), err);
    if (!mesh)
        return;
    float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    float n[9] = {0, 0, 1, 0.6f, 0, 0.8f, 0, -0.6f, 0.8f};
    uint32_t tri[3] = {0, 1, 2};
    memcpy(mesh->positions, p, sizeof p);
    memcpy(mesh->normals, n, sizeof n);
    memcpy(mesh->triangles, tri, sizeof tri);
    asp_cloud *c = NULL;
    CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.points = 3000}, NULL, &c, NULL, err), err);
    double worst = 0.0;
    for (size_t i = 0; c && i < c->count; i++) {
        double x = c->positions[3 * i], y = c->positions[3 * i + 1], w[3] = {1 - x - y, x, y}, e[3], len = 0;
        for (int k = 0; k < 3; k++) {
            e[k] = w[0] * n[k] + w[1] * n[3 + k] + w[2] * n[6 + k];
            len += e[k] * e[k];
        }
        for (int k = 0; k < 3; k++)
            worst = fmax(worst, fabs(e[k] / sqrt(len) - c->normals[3 * i + k]));
    }
    CHECK_MSG(c && worst < 1e-5, "normal error %g", worst);
    asp_cloud_destroy(c);
    asp_mesh_destroy(mesh);
}

static void test_vertices_cover_sphere(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_mesh *mesh = sphere_mesh(24, 40);
    asp_cloud *c = NULL;
    CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_VERTICES}, NULL, &c, NULL, err), err);
    if (!c || !mesh) {
        asp_mesh_destroy(mesh);
        return;
    }
    CHECK(c->count == mesh->vertex_count); /* every vertex is used; output keeps vertex order */
    /* each point of each triangle is within the radius of one of its corners */
    uint64_t s = 5;
    size_t miss = 0;
    double worst_edge_ratio = 0.0;
    for (size_t t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *v = mesh->triangles + 3 * t;
        for (int q = 0; q < 200; q++) {
            double a = urand(&s), b = urand(&s);
            if (a + b > 1)
                a = 1 - a, b = 1 - b;
            double w[3] = {1 - a - b, a, b}, pt[3];
            for (int k = 0; k < 3; k++)
                pt[k] = w[0] * mesh->positions[3 * v[0] + k] + w[1] * mesh->positions[3 * v[1] + k] +
                        w[2] * mesh->positions[3 * v[2] + k];
            int hit = 0;
            for (int k = 0; k < 3; k++) {
                const float *x = c->positions + 3 * (size_t)v[k];
                double d = sqrt((pt[0] - x[0]) * (pt[0] - x[0]) + (pt[1] - x[1]) * (pt[1] - x[1]) +
                                (pt[2] - x[2]) * (pt[2] - x[2]));
                hit |= d <= c->radii[v[k]];
            }
            miss += !hit;
        }
    }
    /* and the radius never exceeds the longest edge of an incident triangle (QSplat's bound) */
    double *longest = calloc(mesh->vertex_count, sizeof(double));
    for (size_t t = 0; longest && t < mesh->triangle_count; t++) {
        const uint32_t *v = mesh->triangles + 3 * t;
        double e = 0.0;
        for (int k = 0; k < 3; k++) {
            const float *x = mesh->positions + 3 * (size_t)v[k], *y = mesh->positions + 3 * (size_t)v[(k + 1) % 3];
            e = fmax(e, sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) + (x[2] - y[2]) * (x[2] - y[2])));
        }
        for (int k = 0; k < 3; k++)
            longest[v[k]] = fmax(longest[v[k]], e);
    }
    for (size_t v = 0; longest && v < mesh->vertex_count; v++)
        worst_edge_ratio = fmax(worst_edge_ratio, c->radii[v] / longest[v]);
    free(longest);
    CHECK_MSG(miss == 0, "%zu triangle points uncovered", miss);
    CHECK_MSG(worst_edge_ratio <= 1.0 + 1e-6, "radius / edge up to %g", worst_edge_ratio);
    /* normals are the (outward) vertex normals */
    CHECK_NEAR(c->normals[2], 1.0, 1e-6);
    asp_cloud_destroy(c);
    asp_mesh_destroy(mesh);
}

static void test_voxel_counts(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_mesh *mesh = plane_mesh(1);
    uint32_t grids[2] = {64, 63};
    for (int g = 0; g < 2; g++) {
        asp_cloud *c = NULL;
        CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_VOXEL, .grid = grids[g]}, NULL, &c,
                                 NULL, err),
                 err);
        if (!c)
            continue;
        size_t n = grids[g];
        CHECK_MSG(c->count == n * n, "grid %zu: %zu points", n, c->count);
        double h = 1.0 / (double)n, worst = 0.0;
        for (size_t i = 0; i < c->count; i++) {
            /* points sit at the cell centres projected onto the square */
            double x = c->positions[3 * i] / h - 0.5, y = c->positions[3 * i + 1] / h - 0.5;
            worst = fmax(worst, fmax(fabs(x - floor(x + 0.5)), fabs(y - floor(y + 0.5))));
            worst = fmax(worst, fabs(c->positions[3 * i + 2]));
        }
        CHECK_MSG(worst < 1e-4, "grid %zu: off-centre by %g cells", n, worst);
        CHECK_NEAR(c->radii[0], 0.5 * sqrt(3.0) * h, 1e-7);
        asp_cloud_destroy(c);
    }
    asp_mesh_destroy(mesh);
    /* a sphere: every voxel point lies on the sphere mesh (within a cell) */
    mesh = sphere_mesh(32, 64);
    asp_cloud *c = NULL;
    CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_VOXEL, .grid = 128}, NULL, &c, NULL, err),
             err);
    if (c) {
        double worst = 0.0, h = 2.0 / 128;
        for (size_t i = 0; i < c->count; i++) {
            const float *p = c->positions + 3 * i;
            worst = fmax(worst, fabs(sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1.0));
        }
        CHECK(worst < h);
        /* about area / h^2 cells, times 1..3 for the surface's slant through the grid */
        double cells = 4 * M_PI / (h * h);
        CHECK_MSG(c->count > cells && c->count < 3 * cells, "%zu cells for ~%g", c->count, cells);
    }
    asp_cloud_destroy(c);
    asp_mesh_destroy(mesh);
}

static void test_determinism(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_mesh *mesh = sphere_mesh(16, 24);
    asp_context one = {.threads = 1}, two = {.threads = 2};
    for (int m = 0; m < 3; m++) {
        asp_cloud *a = NULL, *b = NULL, *d = NULL;
        asp_sample_desc desc = {.method = (asp_sample_method)m, .points = 5000, .grid = 64, .seed = 9};
        CHECK_OK(asp_sample_mesh(mesh, &desc, &one, &a, NULL, err), err);
        CHECK_OK(asp_sample_mesh(mesh, &desc, &two, &b, NULL, err), err);
        desc.seed = 10;
        CHECK_OK(asp_sample_mesh(mesh, &desc, &two, &d, NULL, err), err);
        if (a && b && d) {
            CHECK(a->count == b->count);
            CHECK(memcmp(a->positions, b->positions, 12 * a->count) == 0);
            CHECK(memcmp(a->normals, b->normals, 12 * a->count) == 0);
            CHECK(memcmp(a->radii, b->radii, 4 * a->count) == 0);
            if (m == ASP_SAMPLE_AREA)
                CHECK(memcmp(a->positions, d->positions, 12 * a->count) != 0);
        }
        asp_cloud_destroy(a);
        asp_cloud_destroy(b);
        asp_cloud_destroy(d);
    }
    asp_mesh_destroy(mesh);
}

static void test_bad_input(void)
{
    asp_error err_ = {0}, *err = &err_;
    asp_mesh *mesh = NULL;
    CHECK_OK(asp_mesh_create(3, 1, 0, NULL, &mesh, err), err);
    if (!mesh)
        return;
    uint32_t tri[3] = {0, 1, 2};
    memcpy(mesh->triangles, tri, sizeof tri);
    asp_cloud *c = NULL;
    /* all three vertices at the origin: zero area */
    CHECK(asp_sample_mesh(mesh, NULL, NULL, &c, NULL, err) == ASP_EDEGENERATE);
    CHECK(strstr(err->msg, "zero surface area") != NULL);
    mesh->positions[3] = 1.0f, mesh->positions[7] = 1.0f;
    mesh->triangles[2] = 7;
    CHECK(asp_sample_mesh(mesh, NULL, NULL, &c, NULL, err) == ASP_EFORMAT);
    mesh->triangles[2] = 2;
    mesh->positions[4] = NAN;
    CHECK(asp_sample_mesh(mesh, NULL, NULL, &c, NULL, err) == ASP_EFORMAT);
    CHECK(strstr(err->msg, "vertex 1") != NULL);
    mesh->positions[4] = 0.0f;
    CHECK(asp_sample_mesh(mesh, &(asp_sample_desc){.points = 1}, NULL, &c, NULL, err) == ASP_EINVAL);
    CHECK(asp_sample_mesh(mesh, &(asp_sample_desc){.method = (asp_sample_method)7}, NULL, &c, NULL, err) == ASP_EINVAL);
    CHECK(asp_sample_mesh(mesh, &(asp_sample_desc){.method = ASP_SAMPLE_VOXEL, .grid = 1u << 21}, NULL, &c, NULL,
                          err) == ASP_EINVAL);
    CHECK(c == NULL);
    /* a single triangle samples fine with every method */
    for (int m = 0; m < 3; m++) {
        CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.method = (asp_sample_method)m, .points = 10, .grid = 4},
                                 NULL, &c, NULL, err),
                 err);
        CHECK(c && c->count > 0);
        asp_cloud_destroy(c);
        c = NULL;
    }
    asp_sample_method sm;
    CHECK(asp_sample_method_parse("poisson", &sm, err) == ASP_EINVAL && strstr(err->msg, "poisson"));
    CHECK(asp_sample_method_parse("voxel", &sm, err) == 0 && sm == ASP_SAMPLE_VOXEL);
    asp_mesh_destroy(mesh);
}

TEST_MAIN(TEST_CASE(test_area_density_and_cover), TEST_CASE(test_texture_colours),
          TEST_CASE(test_vertex_and_material_colours), TEST_CASE(test_normal_interpolation),
          TEST_CASE(test_vertices_cover_sphere), TEST_CASE(test_voxel_counts), TEST_CASE(test_determinism),
          TEST_CASE(test_bad_input))
