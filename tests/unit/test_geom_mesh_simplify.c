/*
 * asp_mesh_simplify: target counts, seams and material borders that stay
 * closed, attributes carried over, the error against the original surface,
 * the GPU byte count, and bad input.
 */
#include <float.h>
#include <stdint.h>

#include "amgsplat/geom.h"
#include "amgsplat/mesh.h"
#include "harness.h"

/*
 * A UV sphere of rings x segs quads with a UV seam: the vertices of segment 0
 * and segment segs share positions but carry u = 0 and u = 1, as asp_mesh
 * stores seams. Poles are one vertex per segment (split too). Materials: the
 * upper half 0, the lower half 1 when two_materials.
 */
static asp_mesh *uv_sphere(size_t rings, size_t segs, int two_materials)
{
    size_t nv = (rings + 1) * (segs + 1), nt = 2 * rings * segs - 2 * segs; // one triangle per quad at the poles
    asp_mesh *m = NULL;
    if (asp_mesh_create(nv, nt, ASP_MESH_UVS | ASP_MESH_COLORS, NULL, &m, NULL))
        return NULL;
    const double pi = 3.14159265358979323846;
    for (size_t r = 0; r <= rings; r++)
        for (size_t s = 0; s <= segs; s++) {
            size_t v = r * (segs + 1) + s;
            double th = pi * (double)r / (double)rings, ph = 2 * pi * (double)(s % segs) / (double)segs;
            float p[3] = {(float)(sin(th) * cos(ph)), (float)cos(th), (float)(sin(th) * sin(ph))};
            if (r == 0 || r == rings)
                p[0] = p[2] = 0.0f; // exact pole, so its copies weld
            memcpy(m->positions + 3 * v, p, sizeof p);
            memcpy(m->normals + 3 * v, p, sizeof p);
            m->uvs[2 * v] = (float)s / (float)segs;
            m->uvs[2 * v + 1] = 1.0f - (float)r / (float)rings;
            uint8_t c[4] = {(uint8_t)(s * 255 / segs), (uint8_t)(r * 255 / rings), 7, 255};
            memcpy(m->colors + 4 * v, c, 4);
        }
    size_t t = 0;
    for (size_t r = 0; r < rings; r++)
        for (size_t s = 0; s < segs; s++) {
            uint32_t a = (uint32_t)(r * (segs + 1) + s), b = a + 1, c = a + (uint32_t)(segs + 1), d = c + 1;
            uint32_t q[6] = {a, b, d, a, d, c};
            for (int h = 0; h < 2; h++) {
                if ((r == 0 && h == 0) || (r == rings - 1 && h == 1))
                    continue; // the pole's copies weld: that half is degenerate
                memcpy(m->triangles + 3 * t, q + 3 * h, 3 * sizeof *q);
                m->material_ids[t++] = two_materials && r >= rings / 2;
            }
        }
    if (two_materials) {
        asp_material *mats = asp_calloc(&m->ctx, 2, sizeof *mats);
        mats[0] = m->materials[0];
        mats[1] = m->materials[0];
        snprintf(mats[1].name, sizeof mats[1].name, "lower");
        asp_free(&m->ctx, m->materials);
        m->materials = mats;
        m->material_count = 2;
    }
    return m;
}

/* Vertex id welded by exact position (first vertex with those coordinates). */
static void weld(const asp_mesh *m, uint32_t *id)
{
    for (size_t v = 0; v < m->vertex_count; v++) {
        id[v] = (uint32_t)v;
        for (size_t w = 0; w < v; w++)
            if (memcmp(m->positions + 3 * v, m->positions + 3 * w, 3 * sizeof(float)) == 0) {
                id[v] = (uint32_t)w;
                break;
            }
    }
}

/*
 * Edges, by welded position, used by other than exactly two triangles: 0 on a
 * closed surface, so any tear along a seam or a material border shows.
 */
static size_t open_edges(const asp_mesh *m)
{
    uint32_t *id = malloc((m->vertex_count + 1) * sizeof *id);
    weld(m, id);
    size_t ne = 3 * m->triangle_count, bad = 0;
    uint64_t *e = malloc((ne + 1) * sizeof *e);
    for (size_t t = 0; t < m->triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            uint64_t a = id[m->triangles[3 * t + k]], b = id[m->triangles[3 * t + (k + 1) % 3]];
            e[3 * t + k] = a < b ? (a << 32 | b) : (b << 32 | a);
        }
    /* insertion-free count: sort then run lengths */
    for (size_t i = 1; i < ne; i++)
        for (size_t j = i; j > 0 && e[j - 1] > e[j]; j--) {
            uint64_t x = e[j];
            e[j] = e[j - 1], e[j - 1] = x;
        }
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        while (j < ne && e[j] == e[i])
            j++;
        bad += (j - i) != 2;
        i = j;
    }
    free(e);
    free(id);
    return bad;
}

/* Every output vertex is an input vertex with all its attributes (meshopt collapses onto an end). */
static int vertices_from_input(const asp_mesh *in, const asp_mesh *out)
{
    for (size_t v = 0; v < out->vertex_count; v++) {
        int found = 0;
        for (size_t w = 0; w < in->vertex_count && !found; w++)
            found = memcmp(out->positions + 3 * v, in->positions + 3 * w, 12) == 0 &&
                    memcmp(out->uvs + 2 * v, in->uvs + 2 * w, 8) == 0 &&
                    memcmp(out->colors + 4 * v, in->colors + 4 * w, 4) == 0 &&
                    memcmp(out->normals + 3 * v, in->normals + 3 * w, 12) == 0;
        if (!found)
            return 0;
    }
    return 1;
}

static void test_sphere_seam_stays_closed(void)
{
    asp_mesh *m = uv_sphere(24, 48, 0), *s = NULL;
    CHECK(m && open_edges(m) == 0);
    asp_mesh_simplify_stats st;
    asp_error err = {0};
    CHECK_OK(asp_mesh_simplify(m, &(asp_mesh_simplify_desc){.target_triangles = 400}, NULL, &s, &st, &err), &err);
    if (!s)
        return;
    fprintf(stderr, "sphere: %zu -> %zu triangles (target 400), %zu vertices, error %g\n", st.input_triangles,
            st.output_triangles, st.output_vertices, st.error);
    CHECK(st.output_triangles == s->triangle_count && st.output_vertices == s->vertex_count);
    CHECK(s->triangle_count <= 420 && s->triangle_count >= 300);
    CHECK(!st.short_of_target && !st.sloppy && st.material_groups == 1);
    CHECK_MSG(open_edges(s) == 0, "%zu open edges after simplification", open_edges(s));
    CHECK(vertices_from_input(m, s));
    CHECK(s->uvs && s->colors && s->material_count == 1);
    CHECK(st.error > 0.0 && st.error < 0.05);
    CHECK_OK(asp_mesh_validate(s, "simplified sphere", &err), &err);
    asp_mesh_destroy(s);
    asp_mesh_destroy(m);
}

static void test_two_materials_border_closed(void)
{
    asp_mesh *m = uv_sphere(24, 48, 1), *s = NULL;
    asp_mesh_simplify_stats st;
    asp_error err = {0};
    CHECK_OK(asp_mesh_simplify(m, &(asp_mesh_simplify_desc){.target_triangles = 600}, NULL, &s, &st, &err), &err);
    if (!s)
        return;
    fprintf(stderr, "two materials: %zu -> %zu triangles (target 600)\n", st.input_triangles, st.output_triangles);
    CHECK(st.material_groups == 2 && s->material_count == 2);
    CHECK(strcmp(s->materials[1].name, "lower") == 0);
    CHECK_MSG(open_edges(s) == 0, "%zu open edges", open_edges(s));
    /* both materials keep triangles, each on its own half of the sphere */
    size_t n[2] = {0, 0};
    int wrong_half = 0;
    for (size_t t = 0; t < s->triangle_count; t++) {
        uint32_t k = s->material_ids[t];
        n[k]++;
        for (int c = 0; c < 3; c++) {
            float y = s->positions[3 * (size_t)s->triangles[3 * t + c] + 1];
            wrong_half |= k == 0 ? y < -1e-6f : y > 1e-6f;
        }
    }
    CHECK(n[0] > 100 && n[1] > 100 && !wrong_half);
    CHECK(s->triangle_count <= 630);
    asp_mesh_destroy(s);
    asp_mesh_destroy(m);
}

static void test_copy_error_only_and_flags(void)
{
    asp_mesh *m = uv_sphere(12, 24, 0), *s = NULL;
    asp_error err = {0};
    asp_mesh_simplify_stats st;
    /* no target: a copy */
    CHECK_OK(asp_mesh_simplify(m, NULL, NULL, &s, &st, &err), &err);
    /* the vertices no triangle uses (a pole's last copy) are left out */
    CHECK(s && s->triangle_count == m->triangle_count && s->vertex_count == m->vertex_count - 2 && st.error == 0.0);
    asp_mesh_destroy(s);
    s = NULL;
    /* error only: a tighter bound keeps more triangles */
    size_t loose = 0, tight = 0;
    CHECK_OK(asp_mesh_simplify(m, &(asp_mesh_simplify_desc){.target_error = 0.05}, NULL, &s, &st, &err), &err);
    loose = s ? s->triangle_count : 0;
    CHECK(st.error <= 0.05);
    asp_mesh_destroy(s);
    s = NULL;
    CHECK_OK(asp_mesh_simplify(m, &(asp_mesh_simplify_desc){.target_error = 0.002}, NULL, &s, &st, &err), &err);
    tight = s ? s->triangle_count : 0;
    CHECK(st.error <= 0.002);
    CHECK_MSG(loose < tight && tight <= m->triangle_count, "loose %zu tight %zu", loose, tight);
    asp_mesh_destroy(s);
    s = NULL;
    /* recomputed normals are unit length, point outwards and, on average, along the radius */
    double mean_dot = 0.0;
    CHECK_OK(asp_mesh_simplify(m, &(asp_mesh_simplify_desc){.target_triangles = 300,
                                                           .flags = ASP_MESH_SIMPLIFY_RECOMPUTE_NORMALS},
                               NULL, &s, &st, &err),
             &err);
    int ok = s != NULL;
    for (size_t v = 0; s && v < s->vertex_count; v++) {
        const float *n = s->normals + 3 * v, *p = s->positions + 3 * v;
        int good = fabs(sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) - 1.0) < 1e-4 && n[0] * p[0] + n[1] * p[1] + n[2] * p[2] > 0.0;
        mean_dot += (n[0] * p[0] + n[1] * p[1] + n[2] * p[2]) / (double)s->vertex_count;
        if (!good)
            fprintf(stderr, "vertex %zu: p %g %g %g n %g %g %g\n", v, p[0], p[1], p[2], n[0], n[1], n[2]);
        ok &= good;
    }
    CHECK(ok);
    CHECK_MSG(mean_dot > 0.95, "mean n.p %g", mean_dot);
    asp_mesh_destroy(s);
    asp_mesh_destroy(m);
}

static void test_bad_index(void)
{
    asp_mesh *m = uv_sphere(4, 8, 0), *s = NULL;
    m->triangles[5] = (uint32_t)m->vertex_count;
    asp_error err = {0};
    CHECK(asp_mesh_simplify(m, &(asp_mesh_simplify_desc){.target_triangles = 10}, NULL, &s, NULL, &err) == ASP_EFORMAT);
    CHECK(s == NULL && strstr(err.msg, "triangle 1 uses vertex") != NULL);
    asp_mesh_destroy(m);
}

static void test_gpu_bytes(void)
{
    asp_mesh *m = NULL;
    asp_error err = {0};
    CHECK_OK(asp_mesh_create(10, 4, ASP_MESH_UVS, NULL, &m, &err), &err);
    if (!m)
        return;
    asp_mesh_bytes b;
    CHECK(asp_mesh_gpu_bytes(m, &b) == 10 * 32 + 4 * 12 && b.texture == 0);
    CHECK_OK(asp_image_init(&m->materials[0].texture, 64, 32, &err), &err);
    CHECK(asp_mesh_gpu_bytes(m, &b) == 10 * 32 + 48 + 64 * 32 * 4 * 4 / 3);
    CHECK(b.vertex == 320 && b.index == 48 && b.texture == 10922);
    asp_mesh_destroy(m);
}

/* Distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5), in double. */
static double point_triangle(const double p[3], const float *a, const float *b, const float *c)
{
    double ab[3], ac[3], ap[3], q[3];
    for (int i = 0; i < 3; i++)
        ab[i] = b[i] - a[i], ac[i] = c[i] - a[i], ap[i] = p[i] - a[i];
#define DOT(x, y) ((x)[0] * (y)[0] + (x)[1] * (y)[1] + (x)[2] * (y)[2])
    double d1 = DOT(ab, ap), d2 = DOT(ac, ap);
    if (d1 <= 0 && d2 <= 0)
        return sqrt(DOT(ap, ap));
    double bp[3] = {p[0] - b[0], p[1] - b[1], p[2] - b[2]};
    double d3 = DOT(ab, bp), d4 = DOT(ac, bp);
    if (d3 >= 0 && d4 <= d3)
        return sqrt(DOT(bp, bp));
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int i = 0; i < 3; i++)
            q[i] = ap[i] - v * ab[i];
        return sqrt(DOT(q, q));
    }
    double cp[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    double d5 = DOT(ab, cp), d6 = DOT(ac, cp);
    if (d6 >= 0 && d5 <= d6)
        return sqrt(DOT(cp, cp));
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        for (int i = 0; i < 3; i++)
            q[i] = ap[i] - w * ac[i];
        return sqrt(DOT(q, q));
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int i = 0; i < 3; i++)
            q[i] = bp[i] - w * (c[i] - b[i]);
        return sqrt(DOT(q, q));
    }
    double den = 1.0 / (va + vb + vc), v = vb * den, w = vc * den;
    for (int i = 0; i < 3; i++)
        q[i] = ap[i] - ab[i] * v - ac[i] * w;
    return sqrt(DOT(q, q));
#undef DOT
}

static void test_bunny_1000(void)
{
    char buf[1024];
    const char *path = asp_test_data(buf, sizeof buf, "stanford-bunny.obj");
    if (!path)
        return;
    asp_mesh *m = NULL, *s = NULL;
    asp_error err = {0};
    CHECK_OK(asp_mesh_load(path, NULL, NULL, &m, &err), &err);
    if (!m)
        return;
    asp_mesh_simplify_stats st;
    CHECK_OK(asp_mesh_simplify(m, &(asp_mesh_simplify_desc){.target_triangles = 1000}, NULL, &s, &st, &err), &err);
    if (!s) {
        asp_mesh_destroy(m);
        return;
    }
    CHECK_MSG(fabs((double)s->triangle_count - 1000.0) <= 50.0, "%zu triangles", s->triangle_count);
    /* mean and largest distance of the original vertices to the simplified surface, against the bbox diagonal */
    float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    for (size_t v = 0; v < m->vertex_count; v++)
        for (int c = 0; c < 3; c++)
            lo[c] = fminf(lo[c], m->positions[3 * v + c]), hi[c] = fmaxf(hi[c], m->positions[3 * v + c]);
    double diag = sqrt((double)(hi[0] - lo[0]) * (hi[0] - lo[0]) + (double)(hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (double)(hi[2] - lo[2]) * (hi[2] - lo[2]));
    double sum = 0.0, worst = 0.0;
    for (size_t v = 0; v < m->vertex_count; v++) {
        double p[3] = {m->positions[3 * v], m->positions[3 * v + 1], m->positions[3 * v + 2]}, best = DBL_MAX;
        for (size_t t = 0; t < s->triangle_count; t++) {
            const uint32_t *tri = s->triangles + 3 * t;
            double d = point_triangle(p, s->positions + 3 * (size_t)tri[0], s->positions + 3 * (size_t)tri[1],
                                      s->positions + 3 * (size_t)tri[2]);
            best = d < best ? d : best;
        }
        sum += best;
        worst = best > worst ? best : worst;
    }
    double mean = sum / (double)m->vertex_count;
    fprintf(stderr, "bunny: %zu -> %zu triangles (target 1000), %zu vertices, meshopt error %.4g (%.4g world); "
                    "original vertices to simplified surface: mean %.3g%%, max %.3g%% of the diagonal %.4g\n",
            st.input_triangles, st.output_triangles, st.output_vertices, st.error, st.error_world,
            100 * mean / diag, 100 * worst / diag, diag);
    CHECK(mean / diag < 0.002);
    CHECK(worst / diag < 0.03);
    /* the simplified mesh is much smaller on the GPU */
    CHECK(asp_mesh_gpu_bytes(s, NULL) * 20 < asp_mesh_gpu_bytes(m, NULL));
    asp_mesh_destroy(s);
    asp_mesh_destroy(m);
}

int main(void)
{
    static const asp_test_case cases[] = {
        TEST_CASE(test_sphere_seam_stays_closed), TEST_CASE(test_two_materials_border_closed),
        TEST_CASE(test_copy_error_only_and_flags), TEST_CASE(test_bad_index),
        TEST_CASE(test_gpu_bytes),                TEST_CASE(test_bunny_1000),
    };
    return asp_test_run(__FILE__, cases, sizeof cases / sizeof cases[0]);
}
