/*
 * The decomposition pipeline (journal 2, Fig. 2): neighbourhoods, classifier
 * (2.1), triangle fans and stiffness matrix (2.2), BoomerAMG hierarchy (2.3);
 * plus the accessors of the asp_amg object and level naming (L, L-5, journal
 * Table 2).
 */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amg/internal.h"
#include "util/banned.h"

int asp__amg_alloc(const asp_context *ctx, asp_amg **out, asp_error *err)
{
    asp_amg *a = asp_calloc(ctx, 1, sizeof *a);
    if (!a)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for the decomposition");
    if (ctx)
        a->ctx = *ctx;
    *out = a;
    return 0;
}

void asp_amg_destroy(asp_amg *amg)
{
    if (!amg)
        return;
    asp_context ctx = amg->ctx;
    asp_cloud_destroy(amg->cloud);
    asp_free(&ctx, amg->classifier);
    asp_free(&ctx, amg->tangent);
    asp_amg_csr_destroy(amg->matrix);
    if (amg->prolong)
        for (size_t l = 0; l < amg->nlevels; l++)
            asp_amg_csr_destroy(amg->prolong[l]);
    asp_free(&ctx, amg->prolong);
    asp_free(&ctx, amg->level_size);
    asp_free(&ctx, amg);
}

const asp_cloud *asp_amg_cloud(const asp_amg *amg) { return amg->cloud; }
const asp_frame *asp_amg_frame(const asp_amg *amg) { return &amg->frame; }
const float *asp_amg_classifier(const asp_amg *amg) { return amg->classifier; }
const float *asp_amg_tangent_normals(const asp_amg *amg) { return amg->tangent; }
int asp_amg_has_input_normals(const asp_amg *amg) { return amg->input_normals; }
const asp_amg_info *asp_amg_get_info(const asp_amg *amg) { return &amg->info; }
const asp_amg_csr *asp_amg_matrix(const asp_amg *amg) { return amg->matrix; }
size_t asp_amg_level_count(const asp_amg *amg) { return amg->nlevels; }

size_t asp_amg_level_size(const asp_amg *amg, size_t level)
{
    return level < amg->nlevels ? amg->level_size[level] : 0;
}

const asp_amg_csr *asp_amg_prolongation(const asp_amg *amg, size_t level)
{
    return level >= 1 && level < amg->nlevels ? amg->prolong[level] : NULL;
}

int asp_amg_level_parse(const asp_amg *amg, const char *text, size_t *level, asp_error *err)
{
    const size_t top = amg->nlevels - 1;
    const char *s = text;
    int relative = 0;
    if (s[0] == 'L' || s[0] == 'l') {
        relative = 1;
        s++;
        if (*s == 0) {
            *level = top;
            return 0;
        }
        if (*s != '-')
            goto bad;
        s++;
    }
    if (*s < '0' || *s > '9')
        goto bad;
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || *end)
        goto bad;
    if (v > top)
        return asp_error_set(err, ASP_EINVAL, "no level '%s': the decomposition has levels 0..%zu (L = %zu)", text,
                             top, top);
    *level = relative ? top - (size_t)v : (size_t)v;
    return 0;
bad:
    return asp_error_set(err, ASP_EINVAL, "invalid level '%s': expected L, L-N or an index 0..%zu", text, top);
}

/* Rejects what has no surface: fewer than 3 points, or every point equal. */
static int check_cloud(const asp_cloud *cloud, asp_error *err)
{
    if (cloud->count < 3)
        return asp_error_set(err, ASP_EDEGENERATE, "cannot decompose %zu points: need at least 3 to span a surface",
                             cloud->count);
    if (cloud->count > (size_t)INT32_MAX - 1)
        return asp_error_set(err, ASP_EUNSUPPORTED, "cannot decompose %zu points: at most 2^31-2 are supported",
                             cloud->count);
    int rc = asp_cloud_validate(cloud, err);
    if (rc)
        return rc;
    float lo[3], hi[3];
    rc = asp_cloud_bounds(cloud, lo, hi, err);
    if (rc)
        return rc;
    if (lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2])
        return asp_error_set(err, ASP_EDEGENERATE, "cannot decompose: all %zu points are equal", cloud->count);
    /*
     * Neighbour search (knn.c) and the neighbourhood radius compare float squared distances: past
     * sqrt(FLT_MAX) they overflow to inf, epsilon becomes inf and the file is unreadable (issue #13).
     */
    double diag2 = 0;
    for (int k = 0; k < 3; k++)
        diag2 += ((double)hi[k] - lo[k]) * ((double)hi[k] - lo[k]);
    if (!(diag2 < FLT_MAX))
        return asp_error_set(err, ASP_EUNSUPPORTED,
                             "cannot decompose: the coordinate extent %.3g (bounding-box diagonal) overflows float: "
                             "squared distances need an extent below %.3g; scale the points down", sqrt(diag2),
                             sqrt(FLT_MAX));
    return 0;
}

#ifndef ASP_HAVE_HYPRE
// Nothing to finalise: without hypre no decomposition ever starts MPI (hypre_bridge.c has the real one).
void asp_amg_shutdown(void) {}
#endif

#ifdef ASP_HAVE_HYPRE
/*
 * The decomposition keeps the whole input point set, so domain primitives can
 * be built from an .amg alone (thesis 2.6: the AMG output is stored and only
 * the chosen basis is constructed). Extra properties, faces and comments are
 * not kept: they do not take part in the primitives.
 */
static int copy_points(const asp_cloud *in, const asp_context *ctx, asp_cloud **out, asp_error *err)
{
    const unsigned keep = ASP_ATTR_COLORS | ASP_ATTR_RADII | ASP_ATTR_UVS | ASP_ATTR_LABELS;
    const size_t n = in->count;
    asp_cloud *c;
    int rc = asp_cloud_create(n, ASP_ATTR_NORMALS | (asp_cloud_attrs(in) & keep), ctx, &c, err);
    if (rc)
        return rc;
    memcpy(c->origin, in->origin, sizeof in->origin);
    memcpy(c->positions, in->positions, 3 * n * sizeof(float));
    if (in->normals)
        memcpy(c->normals, in->normals, 3 * n * sizeof(float));
    if (in->colors)
        memcpy(c->colors, in->colors, 4 * n);
    if (in->radii)
        memcpy(c->radii, in->radii, n * sizeof(float));
    if (in->uvs)
        memcpy(c->uvs, in->uvs, 2 * n * sizeof(float));
    if (in->labels)
        memcpy(c->labels, in->labels, n * sizeof(uint32_t));
    c->position_type = in->position_type;
    c->color_type = in->color_type;
    *out = c;
    return 0;
}

static int stage(const asp_context *ctx, const char *name, double f, asp_error *err)
{
    int rc = asp_progress(ctx, name, f);
    if (rc)
        asp_error_set(err, rc, "decomposition canceled during %s", name);
    return rc;
}
#endif

/*
 * The pipeline; with triangles, the fans are the mesh's own (journal eq. 4) instead of journal 2.2's.
 * take (may be NULL) owns cloud: the result keeps it instead of a copy, and it is destroyed on failure.
 */
static int decompose(const asp_cloud *cloud, asp_cloud **take, const uint32_t *triangles, size_t ntris,
                     const asp_amg_desc *desc, const asp_context *ctx, asp_amg **out, asp_error *err)
{
    int rc = check_cloud(cloud, err);
    if (rc)
        return rc;
    asp_amg_desc d;
    rc = asp__amg_resolve_desc(desc, cloud->count, &d, err);
    if (rc)
        return rc;
#ifndef ASP_HAVE_HYPRE
    (void)ctx;
    (void)out;
    (void)triangles;
    (void)ntris;
    (void)take;
    return asp_error_set(err, ASP_EUNSUPPORTED, "cannot decompose: this build has no hypre (ASP_WITH_HYPRE=OFF)");
#else
    asp__amg_hypre_prestart(); /* MPI's start (a singleton's orted) overlaps the neighbour search */
    const size_t n = cloud->count;
    asp_amg *a = NULL;
    asp__amg_nbhd nb = {0};
    asp__amg_fans fans = {0};
    asp_amg_csr **p = NULL, *flat = NULL;
    size_t nlevels = 0;
    asp_index *order = NULL; /* Morton numbering (morton.c); NULL: the input's (a mesh's triangles index it) */
    float *mpos = NULL;      /* the positions in that order, until the matrix is assembled */
    if ((rc = asp__amg_alloc(ctx, &a, err)) != 0)
        return rc;
    if (asp_cloud_frame(cloud, &a->frame, NULL) != 0)
        memset(&a->frame, 0, sizeof a->frame); // nothing to frame: radius 0 ("not known")
    a->input_normals = cloud->normals != NULL;
    if (take) {
        /* the caller's cloud itself: no second copy of the points (issue 19, 28 bytes a point on a scan) */
        a->cloud = *take;
        *take = NULL;
        if (!a->input_normals && (rc = asp_cloud_add_attrs(a->cloud, ASP_ATTR_NORMALS, err)) != 0)
            goto fail;
    } else if ((rc = copy_points(cloud, ctx, &a->cloud, err)) != 0) {
        goto fail;
    }
    a->classifier = asp_alloc(ctx, n * sizeof *a->classifier);
    a->tangent = asp_alloc(ctx, 3 * n * sizeof *a->tangent);
    if (!a->classifier || !a->tangent) {
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the classifier of %zu points", n);
        goto fail;
    }
    const float *pos = a->cloud->positions;

    double t = asp_time_now(), t1;
    if ((rc = stage(ctx, "neighbours", 0, err)) != 0)
        goto fail;
    if (!triangles) {
        /* the distributed decomposition's numbering, so one rank gives this hierarchy (morton.c) */
        if ((rc = asp__amg_morton_order(pos, n, ctx, &order, err)) != 0)
            goto fail;
        if (!(mpos = asp_alloc(ctx, 3 * n * sizeof *mpos))) {
            rc = asp_error_set(err, ASP_ENOMEM, "out of memory for the ordered positions of %zu points", n);
            goto fail;
        }
        for (size_t m = 0; m < n; m++)
            memcpy(mpos + 3 * m, pos + 3 * (size_t)order[m], 3 * sizeof *mpos);
        pos = mpos;
    }
    rc = asp__amg_neighbourhoods(pos, n, &d, ctx, &nb, &a->info.mean_neighbourhood, err);
    if (rc)
        goto fail;
    asp__amg_nbhd_compact(ctx, &nb, triangles ? 0 : d.fan_k);
    t1 = asp_time_now();
    a->info.t_neighbours = t1 - t;
    t = t1;
    if ((rc = stage(ctx, "classifier", 0, err)) != 0)
        goto fail;
    rc = asp__amg_classify(pos, &nb, &d, ctx, a->classifier, a->tangent, err);
    if (rc)
        goto fail;
    t1 = asp_time_now();
    a->info.t_classifier = t1 - t;
    t = t1;
    if ((rc = stage(ctx, "fans", 0, err)) != 0)
        goto fail;
    rc = triangles ? asp__amg_mesh_fans(n, triangles, ntris, ctx, &fans, err)
                   : asp__amg_build_fans(pos, a->tangent, &nb, d.fan_k, ctx, &fans, err);
    if (rc)
        goto fail;
    asp__amg_nbhd_release(ctx, &nb);
    asp__amg_fans_compact(ctx, &fans); /* after the neighbourhoods are gone: not both at once */
    size_t tri_total = 0;
    for (size_t i = 0; i < n; i++)
        tri_total += fans.ntri[i];
    a->info.mean_fan = (double)tri_total / (double)n;
    t1 = asp_time_now();
    a->info.t_fans = t1 - t;
    t = t1;
    if ((rc = stage(ctx, "assembly", 0, err)) != 0)
        goto fail;
    /* with the crease test, also the same fans with C = 1: its reference (hierarchy.c) */
    rc = asp__amg_assemble(pos, a->classifier, &fans, d.stiffness, ctx, &a->matrix, d.crease_cut > 0 ? &flat : NULL,
                           &a->info.positive_offdiag, err);
    if (rc)
        goto fail;
    asp__amg_fans_release(ctx, &fans);
    asp_free(ctx, mpos);
    mpos = NULL;
    /* the tangent normals go back to the input order now; the classifier is the hierarchy's, in its order */
    if (order && (rc = asp__amg_unpermute(a->tangent, n, 3 * sizeof *a->tangent, order, ctx, err)) != 0)
        goto fail;
    if (!a->input_normals)
        memcpy(a->cloud->normals, a->tangent, 3 * n * sizeof *a->tangent);
    a->info.matrix_nnz = a->matrix->row_ptr[n];
    for (size_t i = 0; i < n; i++)
        a->info.isolated_points += a->matrix->row_ptr[i + 1] - a->matrix->row_ptr[i] == 1;
    if (a->info.isolated_points == n) {
        rc = asp_error_set(err, ASP_EDEGENERATE,
                           "cannot decompose %zu points: no point has a triangle fan (colinear or too sparse points)", n);
        goto fail;
    }
    t1 = asp_time_now();
    a->info.t_assembly = t1 - t;
    t = t1;
    if ((rc = stage(ctx, "amg", 0, err)) != 0)
        goto fail;
    if (d.keep_matrix) {
        rc = asp__amg_build_hierarchy(a->matrix, flat, a->classifier, &d, ctx, &nlevels, &p, &a->level_size,
                                      &a->info.repaired_rows, err);
        asp_amg_csr_destroy(flat);
        flat = NULL;
    } else {
        /* A^0 and F^0 go as soon as the hierarchy is done with them: the peak of the AMG stage (issue 19) */
        asp_amg_csr *a0 = a->matrix;
        a->matrix = NULL;
        rc = asp__amg_build_hierarchy_take(&a0, &flat, a->classifier, &d, ctx, &nlevels, &p, &a->level_size,
                                           &a->info.repaired_rows, err);
    }
    if (rc)
        goto fail;
    a->prolong = p;
    a->nlevels = nlevels;
    if (order) {
        /* the result in the input order: per-point arrays and the point rows of P^1 (and A^0's rows and columns) */
        if ((rc = asp__amg_unpermute(a->classifier, n, sizeof *a->classifier, order, ctx, err)) != 0 ||
            (nlevels >= 2 && (rc = asp__amg_csr_unpermute(&a->prolong[1], order, 0, ctx, err)) != 0) ||
            (a->matrix && (rc = asp__amg_csr_unpermute(&a->matrix, order, 1, ctx, err)) != 0))
            goto fail;
        asp_free(ctx, order);
        order = NULL;
    }
    a->info.t_amg = asp_time_now() - t;
    a->info.epsilon = d.epsilon;
    a->info.k_min = d.k_min;
    a->info.k_max = d.k_max;
    a->info.fan_k = d.fan_k;
    a->desc = d;
    *out = a;
    return 0;
fail:
    asp_free(ctx, order);
    asp_free(ctx, mpos);
    asp_amg_csr_destroy(flat);
    asp__amg_nbhd_release(ctx, &nb);
    asp__amg_fans_release(ctx, &fans);
    asp_amg_destroy(a);
    return rc;
#endif
}

int asp_amg_decompose(const asp_cloud *cloud, const asp_amg_desc *desc, const asp_context *ctx, asp_amg **out,
                      asp_error *err)
{
    return decompose(cloud, NULL, NULL, 0, desc, ctx, out, err);
}

int asp_amg_decompose_take(asp_cloud **cloud, const asp_amg_desc *desc, const asp_context *ctx, asp_amg **out,
                           asp_error *err)
{
    ASP_ASSERT(cloud && *cloud);
    int rc = decompose(*cloud, cloud, NULL, 0, desc, ctx, out, err);
    if (rc) {
        asp_cloud_destroy(*cloud); // still here when the checks refused it before the pipeline took it
        *cloud = NULL;
    }
    return rc;
}

int asp_amg_decompose_mesh(const asp_cloud *vertices, const uint32_t *triangles, size_t triangle_count,
                           const asp_amg_desc *desc, const asp_context *ctx, asp_amg **out, asp_error *err)
{
    if (!triangles || triangle_count == 0)
        return asp_error_set(err, ASP_EINVAL, "cannot decompose a mesh without triangles");
    return decompose(vertices, NULL, triangles, triangle_count, desc, ctx, out, err);
}
