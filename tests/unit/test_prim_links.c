/*
 * Links between levels and the view-dependent cut (issue 18 items 1-2,
 * docs/cut.md) on a 20,000-point sample of the bunny: the links reproduce the
 * coarse basis functions (residual), the drawn weights of mixed cuts from 5
 * views sum to 1 +- 0.05 against the .amg's own Psi at every point, a fade
 * keeps that sum and moves weights gradually, and the links survive a .dps
 * round trip.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "amgsplat/amg.h"
#include "amgsplat/mesh.h"
#include "amgsplat/prim.h"
#include "amgsplat/sample.h"
#include "file_forge.h"
#include "harness.h"

static asp_amg *amg;
static asp_dps *dps;
static asp_amg_csr **psi;      /* per stored level */
static uint32_t **basis_prim;  /* per stored level: basis index -> primitive (UINT32_MAX when skipped) */
static int ready, tried;

static void setup(void)
{
    char path[512];
    asp_error err;
    if (tried)
        return;
    tried = 1;
    if (!asp_test_data(path, sizeof path, "stanford-bunny.obj"))
        return;
    asp_mesh *mesh = NULL;
    asp_cloud *cloud = NULL;
    CHECK_OK(asp_mesh_load(path, NULL, NULL, &mesh, &err), &err);
    if (!mesh)
        return;
    CHECK_OK(asp_sample_mesh(mesh, &(asp_sample_desc){.points = 20000, .seed = 1}, NULL, &cloud, NULL, &err), &err);
    asp_mesh_destroy(mesh);
    if (!cloud)
        return;
    CHECK_OK(asp_amg_decompose(cloud, NULL, NULL, &amg, &err), &err);
    asp_cloud_destroy(cloud);
    if (!amg)
        return;
    /* five levels from about 800 to about 30 primitives: L-7 .. L-3 */
    size_t top = asp_amg_level_count(amg) - 1, levels[5];
    CHECK(top >= 8);
    for (size_t i = 0; i < 5; i++)
        levels[i] = top - 7 + i;
    CHECK_OK(asp_prim_build(amg, NULL, levels, 5, NULL, "bunny", NULL, &dps, &err), &err);
    if (!dps)
        return;
    CHECK(dps->level_count == 5);
    CHECK(asp_dps_has_links(dps));
    psi = calloc(dps->level_count, sizeof *psi);
    basis_prim = calloc(dps->level_count, sizeof *basis_prim);
    for (size_t i = 0; i < dps->level_count; i++) {
        const asp_dps_level *lv = &dps->levels[i];
        CHECK_OK(asp_amg_basis(amg, lv->level, NULL, &psi[i], &err), &err);
        basis_prim[i] = malloc(lv->basis_count * sizeof **basis_prim);
        for (size_t b = 0; b < lv->basis_count; b++)
            basis_prim[i][b] = UINT32_MAX;
        for (size_t k = 0; k < lv->prim_count; k++)
            basis_prim[i][lv->prims[k].basis] = (uint32_t)k;
    }
    ready = 1;
}

/* Largest |sum_f weight_f Psi_f(x) - 1| over the points; weights by level then primitive, as asp_dps_cut_target. */
static double pou_deviation(const float *weights, double *mean_dev)
{
    size_t n = psi[0]->rows, base = 0;
    double *sum = calloc(n, sizeof *sum), worst = 0, mean = 0;
    for (size_t i = 0; i < dps->level_count; i++) {
        const asp_amg_csr *m = psi[i];
        for (size_t x = 0; x < n; x++)
            for (size_t e = m->row_ptr[x]; e < m->row_ptr[x + 1]; e++) {
                uint32_t f = basis_prim[i][m->col[e]];
                if (f != UINT32_MAX)
                    sum[x] += weights[base + f] * m->val[e];
            }
        base += dps->levels[i].prim_count;
    }
    for (size_t x = 0; x < n; x++) {
        double d = fabs(sum[x] - 1);
        worst = d > worst ? d : worst;
        mean += d;
    }
    free(sum);
    if (mean_dev)
        *mean_dev = mean / (double)n;
    return worst;
}

/* A camera at distance dist x the frame radius from the centre along dir, 512 px high, 45 degrees. */
static asp_dps_cut_view view_from(const double dir[3], double dist, double tolerance)
{
    asp_dps_cut_view v = {.pixels_per_unit = 512 / (2 * tan(22.5 * 3.14159265358979 / 180)), .tolerance = tolerance};
    double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    for (int k = 0; k < 3; k++)
        v.eye[k] = dps->frame.center[k] + dir[k] / len * dist * dps->frame.radius;
    return v;
}

/* Each stored pair of levels: sum_j w(j -> k) Psi_j against Psi_k at the points. */
static void test_links_residual(void)
{
    setup();
    if (!ready)
        return;
    size_t n = psi[0]->rows;
    for (size_t i = 0; i + 1 < dps->level_count; i++) {
        const asp_dps_level *lv = &dps->levels[i], *up = &dps->levels[i + 1];
        CHECK(lv->link_first && lv->link_first[lv->prim_count] == lv->link_total);
        double *rec = calloc(n * up->prim_count, sizeof *rec), worst = 0;
        for (size_t x = 0; x < n; x++)
            for (size_t e = psi[i]->row_ptr[x]; e < psi[i]->row_ptr[x + 1]; e++) {
                uint32_t j = basis_prim[i][psi[i]->col[e]];
                if (j == UINT32_MAX)
                    continue;
                for (size_t q = lv->link_first[j]; q < lv->link_first[j + 1]; q++)
                    rec[x * up->prim_count + lv->link_parent[q]] += lv->link_weight[q] * psi[i]->val[e];
            }
        for (size_t x = 0; x < n; x++)
            for (size_t e = psi[i + 1]->row_ptr[x]; e < psi[i + 1]->row_ptr[x + 1]; e++) {
                uint32_t k = basis_prim[i + 1][psi[i + 1]->col[e]];
                if (k != UINT32_MAX)
                    rec[x * up->prim_count + k] -= psi[i + 1]->val[e];
            }
        for (size_t q = 0; q < n * up->prim_count; q++)
            worst = fabs(rec[q]) > worst ? fabs(rec[q]) : worst;
        free(rec);
        fprintf(stderr, "links %zu -> %zu (%zu -> %zu primitives, %zu links): max |sum w Psi_j - Psi_k| = %.2e\n", i,
                i + 1, lv->prim_count, up->prim_count, lv->link_total, worst);
        CHECK_MSG(worst < 0.05, "level %zu: link residual %g", i, worst);
    }
}

static const double dirs[5][3] = {{0, 0, 1}, {1, 0.3, 0}, {-1, 0.5, -1}, {0, 1, 0.2}, {0.3, -0.2, -1}};
static const double dists[5] = {1.6, 2.5, 4, 8, 1.3};

static void test_cut_partition_of_unity(void)
{
    setup();
    if (!ready)
        return;
    asp_error err;
    asp_dps_cut *cut = NULL;
    CHECK_OK(asp_dps_cut_create(dps, 0, NULL, &cut, &err), &err);
    if (!cut)
        return;
    size_t total = asp_dps_cut_target_count(cut);
    float *w = malloc(total * sizeof *w);
    for (int v = 0; v < 5; v++) {
        asp_dps_cut_view view = view_from(dirs[v], dists[v], 0.5);
        size_t drawn = asp_dps_cut_target(cut, &view, w);
        /* a mixed cut: primitives of at least two levels */
        size_t per[8] = {0}, base = 0, levels_used = 0;
        for (size_t i = 0; i < dps->level_count; i++) {
            for (size_t k = 0; k < dps->levels[i].prim_count; k++)
                per[i] += w[base + k] > 0;
            levels_used += per[i] > 0;
            base += dps->levels[i].prim_count;
        }
        double mean = 0, dev = pou_deviation(w, &mean);
        fprintf(stderr, "view %d (distance %.1f r): %zu drawn (per level %zu %zu %zu %zu %zu), max |sum d Psi - 1| = "
                "%.2e, mean %.2e\n", v, dists[v], drawn, per[0], per[1], per[2], per[3], per[4], dev, mean);
        CHECK_MSG(levels_used >= 2, "view %d: the cut uses %zu level(s)", v, levels_used);
        CHECK_MSG(dev <= 0.05, "view %d: partition of unity off by %g", v, dev);
    }
    /* tolerance 0 is the finest level everywhere; a huge one the coarsest */
    asp_dps_cut_view fine = view_from(dirs[0], 3, 0), coarse = view_from(dirs[0], 3, 1e9);
    CHECK(asp_dps_cut_target(cut, &fine, w) == dps->levels[0].prim_count);
    CHECK(pou_deviation(w, NULL) <= 0.05);
    CHECK(asp_dps_cut_target(cut, &coarse, w) == dps->levels[dps->level_count - 1].prim_count);
    CHECK(pou_deviation(w, NULL) <= 0.05);
    free(w);
    asp_dps_cut_destroy(cut);
}

/* A change of the cut fades over 0.25 s: the weights move by at most dt / 0.25 of their change per step and the
 * partition of unity holds at every step. */
static void test_cut_fade(void)
{
    setup();
    if (!ready)
        return;
    asp_error err;
    asp_dps_cut *cut = NULL;
    CHECK_OK(asp_dps_cut_create(dps, 0.25, NULL, &cut, &err), &err);
    if (!cut)
        return;
    size_t total = asp_dps_cut_target_count(cut);
    float *w = calloc(total, sizeof *w), *prev = calloc(total, sizeof *prev), *a = calloc(total, sizeof *a),
          *b = calloc(total, sizeof *b);
    asp_dps_cut_view near = view_from(dirs[0], 1.3, 0.5), far = view_from(dirs[0], 8, 0.5);
    asp_dps_cut_target(cut, &near, a);
    asp_dps_cut_target(cut, &far, b);
    CHECK(memcmp(a, b, total * sizeof *a) != 0);
    CHECK_OK(asp_dps_cut_update(cut, &near, 0, &err), &err);
    const asp_dps_cut_item *it;
    size_t n = asp_dps_cut_items(cut, &it);
    CHECK(!asp_dps_cut_fading(cut));
    double worst = 0, worst_step = 0;
    int steps = 0;
    for (int s = 0; s < 8; s++) {
        memset(prev, 0, total * sizeof *prev);
        size_t base[8] = {0};
        for (size_t i = 1; i < dps->level_count; i++)
            base[i] = base[i - 1] + dps->levels[i - 1].prim_count;
        for (size_t q = 0; q < n; q++)
            prev[base[it[q].level] + it[q].prim] = it[q].weight;
        CHECK_OK(asp_dps_cut_update(cut, &far, 0.05, &err), &err);
        n = asp_dps_cut_items(cut, &it);
        memset(w, 0, total * sizeof *w);
        for (size_t q = 0; q < n; q++)
            w[base[it[q].level] + it[q].prim] = it[q].weight;
        double dev = pou_deviation(w, NULL);
        worst = dev > worst ? dev : worst;
        for (size_t g = 0; g < total; g++) {
            double step = fabs(w[g] - prev[g]), allowed = fabs(b[g] - a[g]) * 0.05 / 0.25 + 1e-5;
            if (step > allowed && step - allowed > worst_step)
                worst_step = step - allowed;
        }
        steps += asp_dps_cut_fading(cut);
    }
    fprintf(stderr, "fade: 8 steps of 50 ms, fading for %d, max |sum d Psi - 1| during the fade = %.2e, largest "
            "step beyond dt/T = %g\n", steps, worst, worst_step);
    CHECK_MSG(steps == 4, "the fade lasted %d steps of 50 ms, expected 4 (0.25 s)", steps);
    CHECK(worst <= 0.05);
    CHECK(worst_step == 0);
    for (size_t g = 0; g < total; g++)
        CHECK(fabsf(w[g] - b[g]) < 1e-6f);
    free(w), free(prev), free(a), free(b);
    asp_dps_cut_destroy(cut);
}

/* The links and the version-3 options survive the file; damaged links are refused. */
static void test_links_file(void)
{
    setup();
    if (!ready)
        return;
    asp_error err;
    const char *path = "test_prim_links.dps";
    dps->desc.brightness = 0.25, dps->desc.no_model_colors = 1;
    CHECK_OK(asp_dps_save(dps, path, &err), &err);
    dps->desc.brightness = 0, dps->desc.no_model_colors = 0;
    asp_dps *back = NULL;
    CHECK_OK(asp_dps_load(path, NULL, &back, &err), &err);
    if (!back)
        return;
    CHECK(back->desc.brightness == 0.25 && back->desc.no_model_colors == 1);
    CHECK(asp_dps_has_links(back));
    for (size_t i = 0; i < dps->level_count; i++) {
        const asp_dps_level *x = &dps->levels[i], *y = &back->levels[i];
        CHECK(x->link_total == y->link_total && x->strict == y->strict);
        if (x->link_first && y->link_first) {
            CHECK(memcmp(x->link_first, y->link_first, (x->prim_count + 1) * 4) == 0);
            CHECK(memcmp(x->link_parent, y->link_parent, x->link_total * 4) == 0);
            CHECK(memcmp(x->link_weight, y->link_weight, x->link_total * 4) == 0);
        }
    }
    asp_dps_destroy(back);
    /* damaged links are refused with the level, primitive and field: a weight above 1, a parent beyond the
     * next level, a range that does not start at 0 (level 0's lists follow its header, primitives and
     * neighbours) */
    size_t size = 0;
    unsigned char *bytes = forge_slurp(path, &size);
    const asp_dps_level *l0 = &dps->levels[0];
    const size_t first_at = 96 + 128 + 4 + strlen("bunny") + 112 + 124 * l0->prim_count + 4 * l0->neighbour_total,
                 pair_at = first_at + 4 * (l0->prim_count + 1);
    const struct { size_t at; uint32_t value; const char *field; } bad[] = {
        {pair_at + 4, 0x40000000u /* 2.0f */, "weight 2"},
        {pair_at, 1000000u, "names primitive 1000000"},
        {first_at, 1u, "link range start 1"}};
    for (size_t i = 0; bytes && i < sizeof bad / sizeof bad[0]; i++) {
        unsigned char *b = malloc(size);
        memcpy(b, bytes, size);
        forge_put_le(b + bad[i].at, bad[i].value, 4);
        forge_fix(b, size, 24);
        asp_dps *x = NULL;
        CHECK(asp_dps_load_memory(b, size, "forged.dps", NULL, &x, &err) == ASP_EFORMAT && !x);
        CHECK_MSG(strstr(err.msg, bad[i].field) != NULL, "%s: %s", bad[i].field, err.msg);
        free(b);
    }
    free(bytes);
    /* a version-2 file of the two coarsest levels (no links, 96-byte level records) loads, and a cut of it is
     * refused with the reason: forged from the version-3 bytes by cutting each level's 16 link bytes and lists */
    asp_dps two = *dps;
    two.levels = &dps->levels[dps->level_count - 2];
    two.level_count = 2;
    CHECK_OK(asp_dps_save(&two, path, &err), &err);
    bytes = forge_slurp(path, &size);
    unsigned char *v2 = bytes ? malloc(size) : NULL;
    if (v2) {
        size_t in = 96 + 128 + 4 + strlen("bunny"), out = in;
        memcpy(v2, bytes, in);
        for (size_t i = 0; i < 2; i++) {
            const asp_dps_level *lv = &two.levels[i];
            size_t atlas = 4 * (size_t)lv->atlas.width * lv->atlas.height * (lv->normal_atlas.width ? 2 : 1);
            size_t body = 124 * lv->prim_count + 4 * lv->neighbour_total;
            memcpy(v2 + out, bytes + in, 96);
            memcpy(v2 + out + 96, bytes + in + 112, body);
            size_t links = lv->link_first ? 4 * (lv->prim_count + 1) + 8 * lv->link_total : 0;
            memcpy(v2 + out + 96 + body, bytes + in + 112 + body + links, atlas);
            in += 112 + body + links + atlas;
            out += 96 + body + atlas;
        }
        CHECK(in + 4 == size);
        out += 4;
        forge_put_le(v2 + 8, 2, 4);
        forge_fix(v2, out, 24);
        asp_dps *old = NULL;
        CHECK_OK(asp_dps_load_memory(v2, out, "v2.dps", NULL, &old, &err), &err);
        if (old) {
            CHECK(old->level_count == 2 && !asp_dps_has_links(old));
            CHECK(old->levels[0].prim_count == two.levels[0].prim_count && old->desc.brightness == 0);
            asp_dps_cut *cut = NULL;
            CHECK(asp_dps_cut_create(old, 0, NULL, &cut, &err) == ASP_EINVAL && !cut);
            CHECK_MSG(strstr(err.msg, "rebuild") != NULL, "%s", err.msg);
            asp_dps_destroy(old);
        }
    }
    free(v2);
    free(bytes);
    /* a cut needs links: a dps whose links were dropped is refused with a message */
    asp_dps_level *lv = &dps->levels[0];
    uint32_t *keep = lv->link_first;
    lv->link_first = NULL;
    asp_dps_cut *cut = NULL;
    CHECK(asp_dps_cut_create(dps, 0, NULL, &cut, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "no links") != NULL);
    lv->link_first = keep;
    remove(path);
}

TEST_MAIN(TEST_CASE(test_links_residual), TEST_CASE(test_cut_partition_of_unity), TEST_CASE(test_cut_fade),
          TEST_CASE(test_links_file))
