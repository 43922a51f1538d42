/*
 * The decomposition on MPI ranks (issue 19; journal 2.1-2.3 as decompose.c),
 * the driver of its stages: Morton-ordered points with a halo
 * (distributed_points.c), the neighbourhood radius and epsilon over every
 * rank, the serial kernels on each rank's points and halo, the stiffness rows
 * of owned points completed across rank borders (distributed_rows.c), the
 * hierarchy level by level (distributed_hierarchy.c, distributed_repair.c),
 * the basis Psi^l = P^1 ... P^l (distributed_basis.c) and the .amg file
 * (distributed_write.c).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amgsplat/amg_distributed.h"
#include "util/banned.h"

int asp_amg_mpi_ranks(void)
{
    /* Open MPI, MPICH/Hydra and PMIx, Slurm's srun: the launcher's word, read before MPI starts */
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; i++) {
        const char *v = getenv(vars[i]);
        if (v && *v) {
            long n = strtol(v, NULL, 10);
            if (n >= 1 && n < 1L << 24)
                return (int)n;
        }
    }
    return 1;
}

#ifndef ASP_HAVE_HYPRE
int asp_amg_decompose_distributed(const char *in_path, const char *out_path, const asp_amg_desc *desc, double tau,
                                  const asp_context *ctx, asp_amg_dist_info *info, asp_error *err)
{
    (void)in_path, (void)out_path, (void)desc, (void)tau, (void)ctx, (void)info;
    return asp_error_set(err, ASP_EUNSUPPORTED, "cannot decompose on MPI ranks: this build has no hypre");
}
void asp_amg_distributed_shutdown(void) {}
#else
#include <sys/resource.h>

#include "amgsplat/geom.h"

#include "amg/distributed.h"

/* ---- neighbourhood radius and halo ---- */

/* The global order statistic: the smallest v with at least want values <= v among every rank's vals[i * stride]. */
static float global_select(const asp__dist *d, const float *vals, size_t n, size_t stride, unsigned long long want)
{
    uint32_t lo = 0, hi = 0x7f800000u; /* non-negative floats order as their bits */
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        unsigned long long c = 0, all = 0;
        for (size_t i = 0; i < n; i++) {
            uint32_t b;
            memcpy(&b, &vals[i * stride], 4);
            c += b <= mid;
        }
        MPI_Allreduce(&c, &all, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
        if (all >= want)
            hi = mid;
        else
            lo = mid + 1;
    }
    float v;
    memcpy(&v, &lo, 4);
    return v;
}

/* k nearest among the n points at pos (k < n): squared distances into a new array. */
static int knn_dist2(const asp__dist *d, const float *pos, size_t n, size_t k, float **out, asp_error *err)
{
    asp_kdtree *tree = NULL;
    asp_index *idx = NULL;
    float *d2 = NULL;
    int rc = asp_kdtree_create(pos, n, 3 * sizeof(float), &d->ctx, &tree, err);
    if (!rc) {
        idx = asp_alloc(&d->ctx, n * k * sizeof *idx);
        d2 = asp_alloc(&d->ctx, n * k * sizeof *d2);
        rc = idx && d2 ? asp_knn_all(tree, k, idx, d2, &d->ctx, err)
                       : asp_error_set(err, ASP_ENOMEM, "out of memory for %zu x %zu neighbours", n, k);
    }
    asp_kdtree_destroy(tree);
    asp_free(&d->ctx, idx);
    if (rc)
        asp_free(&d->ctx, d2);
    else
        *out = d2;
    return rc;
}

/*
 * Each owned point's k_max-th neighbour distance among the rank's own points
 * bounds its true one from above; epsilon (journal 2.1) is the global median
 * k_min-th distance, found exactly by bisection on the float bits (the serial
 * select_kth). The halo radius is capped at twice the median k_max-th
 * distance: a few points of a rank's piece of the Morton curve lie apart from
 * the rest, and their uncapped balls spanned much of the model (246k halo
 * points for 1M on 2 ranks). halo_and_neighbourhoods checks the cap.
 */
static int radii_and_epsilon(const asp__dist *d, const asp__dist_points *pts, asp_amg_desc *desc, float *radius,
                             asp_error *err)
{
    const size_t n = pts->n_own, k = desc->k_max;
    float *d2 = NULL;
    int rc = 0;
    if (n <= k)
        rc = asp_error_set(err, ASP_EINVAL,
                           "rank %d holds %zu points, fewer than k_max + 1 = %zu: use fewer ranks for %zu points",
                           d->rank, n, k + 1, pts->n_global);
    if (!rc)
        rc = knn_dist2(d, pts->pos, n, k, &d2, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    const float cap = 2.0f * sqrtf(global_select(d, d2 + k - 1, n, k, pts->n_global / 2 + 1));
    for (size_t i = 0; i < n; i++)
        radius[i] = fminf(sqrtf(d2[i * k + k - 1]), cap) * (1.0f + 1e-5f) + 1e-30f;
    if (desc->epsilon == 0) {
        desc->epsilon = sqrt((double)global_select(d, d2 + desc->k_min - 1, n, k, pts->n_global / 2 + 1));
        if (!(desc->epsilon > 0))
            rc = asp_error_set(err, ASP_EDEGENERATE,
                               "cannot decompose: most points coincide with %zu others (no neighbourhood radius)",
                               desc->k_min);
    }
    asp_free(&d->ctx, d2);
    return rc;
}

/* ---- the pipeline ---- */

static double peak_rss_mb(void)
{
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) == 0 ? (double)ru.ru_maxrss / 1024.0 : 0;
}

/* The frame of asp_cloud_frame over every rank: box centre, farthest point plus the largest disc radius. */
static void frame_of(const asp__dist *d, const asp__dist_points *pts, asp_frame *frame)
{
    double far2 = 0, all2 = 0, rmax = 0, rall = 0;
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = 0.5 * ((double)pts->lo[k] + pts->hi[k]);
    for (size_t i = 0; i < pts->n_own; i++) {
        double s = 0;
        for (int k = 0; k < 3; k++)
            s += ((double)pts->pos[3 * i + k] - c[k]) * ((double)pts->pos[3 * i + k] - c[k]);
        far2 = fmax(far2, s);
        if (pts->radii)
            rmax = fmax(rmax, pts->radii[i]);
    }
    MPI_Allreduce(&far2, &all2, 1, MPI_DOUBLE, MPI_MAX, d->comm);
    MPI_Allreduce(&rmax, &rall, 1, MPI_DOUBLE, MPI_MAX, d->comm);
    if (!pts->radii) {
        /* asp_cloud_default_radius: discs twice the size that would cover half the box's surface */
        double e[3] = {(double)pts->hi[0] - pts->lo[0], (double)pts->hi[1] - pts->lo[1],
                       (double)pts->hi[2] - pts->lo[2]};
        double area = e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
        rall = area > 0 ? 2 * sqrt(area / (3.14159265358979323846 * (double)pts->n_global))
                        : fmax(e[0], fmax(e[1], e[2])) / (double)pts->n_global;
    }
    for (int k = 0; k < 3; k++)
        frame->center[k] = c[k] + pts->origin[k];
    frame->radius = sqrt(all2) + rall;
}

typedef struct run {
    asp__dist d;
    asp_amg_desc desc;
    int auto_epsilon; /* desc.epsilon was not given: the median k_min-th distance */
    asp__dist_points pts;
    float *radius, *cls, *tangent;
    asp__amg_nbhd nb;
    asp__amg_fans fans;
    asp_amg_csr *la, *lf, *a, *f;
    asp__dist_hier h;
} run;

static void run_release(run *r)
{
    const asp_context *ctx = &r->d.ctx;
    asp__dist_points_release(ctx, &r->pts);
    asp_free(ctx, r->radius);
    asp_free(ctx, r->cls);
    asp_free(ctx, r->tangent);
    asp__amg_nbhd_release(ctx, &r->nb);
    asp__amg_fans_release(ctx, &r->fans);
    asp_amg_csr_destroy(r->la);
    asp_amg_csr_destroy(r->lf);
    asp_amg_csr_destroy(r->a);
    asp_amg_csr_destroy(r->f);
    asp__dist_hier_release(ctx, &r->h);
}

/* Neighbourhoods, classifier, fans and stiffness rows of the owned points (journal 2.1-2.2). */
static float dist2(const float *x, const float *y)
{
    return (x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) + (x[2] - y[2]) * (x[2] - y[2]);
}

/*
 * Epsilon of one process (the median k_min-th neighbour distance, journal
 * 2.1): the estimate from each rank's own points is a little high at rank
 * borders (0.6% on a 20k bunny on 2 ranks); with the halo the owned points'
 * k_min-th neighbours are exact, so the median is taken again and the
 * neighbourhood sizes follow it.
 */
static int exact_epsilon(run *r, asp_error *err)
{
    const asp__dist_points *pts = &r->pts;
    const size_t n = pts->n_own, kmin = r->desc.k_min, kmax = r->desc.k_max;
    float *kth = asp_alloc(&r->d.ctx, (n + 1) * sizeof *kth);
    int rc = asp__dist_agree(&r->d, kth ? 0 : asp_error_set(err, ASP_ENOMEM, "out of memory for %zu distances", n), err);
    if (rc)
        return rc;
    for (size_t i = 0; i < n; i++)
        kth[i] = dist2(pts->pos + 3 * i, pts->pos + 3 * (size_t)r->nb.nbr[i * kmax + kmin - 1]);
    r->desc.epsilon = sqrt((double)global_select(&r->d, kth, n, 1, pts->n_global / 2 + 1));
    asp_free(&r->d.ctx, kth);
    const float eps2 = (float)(r->desc.epsilon * r->desc.epsilon);
    for (size_t i = 0; i < n; i++) {
        size_t m = kmin;
        while (m < kmax && dist2(pts->pos + 3 * i, pts->pos + 3 * (size_t)r->nb.nbr[i * kmax + m]) <= eps2)
            m++;
        r->nb.nn[i] = (uint16_t)m;
    }
    return 0;
}

/*
 * The halo, then the neighbourhoods N(x) of journal 2.1 on the rank's points
 * and halo. N(x_i) is the one of a single process when everything within its
 * farthest member, and within epsilon when it stopped short of k_max, lay
 * within radius[i] (all of that was sent). Otherwise that distance becomes
 * radius[i] and the halo is made again (none was needed on the bunny).
 */
static int halo_and_neighbourhoods(run *r, asp_amg_dist_info *info, asp_error *err)
{
    asp__dist *d = &r->d;
    asp__dist_points *pts = &r->pts;
    const size_t kmax = r->desc.k_max;
    for (int round = 0;; round++) {
        double t = asp_time_now(), mean = 0;
        int rc = d->size > 1 ? asp__dist_halo(d, pts, r->radius, err) : 0;
        info->t_halo += asp_time_now() - t;
        t = asp_time_now();
        if (!rc)
            rc = asp__amg_neighbourhoods(pts->pos, pts->n_own + pts->n_ghost, &r->desc, &d->ctx, &r->nb, &mean, err);
        info->amg.t_neighbours += asp_time_now() - t;
        if ((rc = asp__dist_agree(d, rc, err)) != 0)
            return rc;
        if (r->auto_epsilon && d->size > 1 && (rc = exact_epsilon(r, err)) != 0)
            return rc;
        unsigned long long short_ = 0, all = 0;
        for (size_t i = 0; d->size > 1 && i < pts->n_own; i++) {
            const size_t m = r->nb.nn[i];
            const float *x = pts->pos + 3 * i, *y = pts->pos + 3 * (size_t)r->nb.nbr[i * kmax + m - 1];
            float far = sqrtf((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                              (x[2] - y[2]) * (x[2] - y[2]));
            if (m < kmax)
                far = fmaxf(far, (float)r->desc.epsilon);
            if (far > r->radius[i]) {
                r->radius[i] = far * (1.0f + 1e-5f) + 1e-30f;
                short_++;
            }
        }
        MPI_Allreduce(&short_, &all, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, d->comm);
        if (all == 0)
            return 0;
        asp__amg_nbhd_release(&d->ctx, &r->nb);
        if (round == 8)
            return asp_error_set(err, ASP_ESOLVER, "the halo did not close after 8 rounds (%llu points short)", all);
    }
}

/* Classifier, fans and stiffness rows of the owned points (journal 2.1-2.2). */
static int local_stages(run *r, asp_amg_dist_info *info, asp_error *err)
{
    asp__dist *d = &r->d;
    asp__dist_points *pts = &r->pts;
    const size_t n = pts->n_own, nl = pts->n_own + pts->n_ghost;
    int rc = 0;
    unsigned long long nn = 0;
    for (size_t i = 0; i < n; i++)
        nn += r->nb.nn[i];
    info->amg.mean_neighbourhood = (double)asp__dist_sum(d, nn) / (double)pts->n_global;
    double t = asp_time_now();
    r->cls = asp_alloc(&d->ctx, (nl + 1) * sizeof *r->cls);
    r->tangent = asp_alloc(&d->ctx, (3 * nl + 3) * sizeof *r->tangent);
    rc = r->cls && r->tangent ? asp__amg_classify(pts->pos, &r->nb, &r->desc, &d->ctx, r->cls, r->tangent, err)
                              : asp_error_set(err, ASP_ENOMEM, "out of memory for the classifier of %zu points", nl);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    /* a halo point's own neighbourhood is cut at the halo's edge: its owner's values are the right ones */
    rc = asp__dist_fetch(d, pts->starts, r->cls, sizeof *r->cls, pts->ghost_gid, pts->n_ghost, r->cls + n, err);
    if (!rc)
        rc = asp__dist_fetch(d, pts->starts, r->tangent, 3 * sizeof *r->tangent, pts->ghost_gid, pts->n_ghost,
                             r->tangent + 3 * n, err);
    if (rc)
        return rc;
    info->amg.t_classifier = asp_time_now() - t;
    t = asp_time_now();
    rc = asp__amg_build_fans(pts->pos, r->tangent, &r->nb, r->desc.fan_k, &d->ctx, &r->fans, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    asp__amg_nbhd_release(&d->ctx, &r->nb);
    unsigned long long tri = 0;
    for (size_t i = 0; i < nl; i++) {
        if (i >= n)
            r->fans.ntri[i] = 0; /* a halo point's row belongs to its owner */
        tri += r->fans.ntri[i];
    }
    info->amg.mean_fan = (double)asp__dist_sum(d, tri) / (double)pts->n_global;
    info->amg.t_fans = asp_time_now() - t;
    t = asp_time_now();
    const int crease = r->desc.crease_cut > 0;
    size_t positive = 0;
    rc = asp__amg_assemble(pts->pos, r->cls, &r->fans, ASP_AMG_STIFFNESS_UNCLAMPED, &d->ctx, &r->la,
                           crease ? &r->lf : NULL, &positive, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    asp__amg_fans_release(&d->ctx, &r->fans);
    rc = asp__dist_global_rows(d, pts, &r->la, &r->lf, r->desc.stiffness, &r->a, &r->f, &info->amg.positive_offdiag, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        return rc;
    asp_amg_csr_destroy(r->la);
    asp_amg_csr_destroy(r->lf);
    r->la = r->lf = NULL;
    unsigned long long isolated = 0;
    for (size_t i = 0; i < n; i++)
        isolated += r->a->row_ptr[i + 1] - r->a->row_ptr[i] == 1;
    info->amg.isolated_points = (size_t)asp__dist_sum(d, isolated);
    info->amg.matrix_nnz = (size_t)asp__dist_sum(d, r->a->row_ptr[n]);
    if (info->amg.isolated_points == pts->n_global)
        return asp_error_set(err, ASP_EDEGENERATE,
                             "cannot decompose %zu points: no point has a triangle fan (colinear or too sparse points)",
                             pts->n_global);
    info->amg.t_assembly = asp_time_now() - t;
    return 0;
}

int asp_amg_decompose_distributed(const char *in_path, const char *out_path, const asp_amg_desc *desc, double tau,
                                  const asp_context *ctx, asp_amg_dist_info *info, asp_error *err)
{
    run r;
    memset(&r, 0, sizeof r);
    if (ctx)
        r.d.ctx = *ctx;
    asp__dist *d = &r.d;
    asp_amg_dist_info inf;
    memset(&inf, 0, sizeof inf);
    if (info)
        memset(info, 0, sizeof *info);
    int rc = asp__dist_start(d, err);
    if (rc)
        return rc;
    const double t0 = asp_time_now();
    inf.rank = d->rank;
    inf.ranks = d->size;
    const int figures = tau != ASP_AMG_DIST_NO_FIGURES;
    if (figures && !(tau >= 0 && tau < 1))
        return asp_error_set(err, ASP_EINVAL, "invalid domain threshold %g: expected a value in [0, 1)", tau);
    rc = asp__dist_read_sorted(d, in_path, &r.pts, err);
    if (!rc)
        rc = asp__dist_agree(d, asp__amg_resolve_desc(desc, r.pts.n_global, &r.desc, err), err);
    if (rc)
        goto done;
    r.auto_epsilon = r.desc.epsilon == 0;
    inf.points = r.pts.n_global;
    inf.own_points_min = SIZE_MAX;
    for (int q = 0; q < d->size; q++) {
        size_t c = r.pts.starts[q + 1] - r.pts.starts[q];
        inf.own_points_min = c < inf.own_points_min ? c : inf.own_points_min;
        inf.own_points_max = c > inf.own_points_max ? c : inf.own_points_max;
    }
    inf.t_read = asp_time_now() - t0;
    double t = asp_time_now();
    r.radius = asp_alloc(&d->ctx, (r.pts.n_own + 1) * sizeof *r.radius);
    /* on one rank there is no halo: the neighbourhoods find epsilon themselves, as in one process */
    rc = !r.radius ? asp_error_set(err, ASP_ENOMEM, "out of memory for %zu radii", r.pts.n_own)
         : d->size > 1 ? radii_and_epsilon(d, &r.pts, &r.desc, r.radius, err)
                       : 0;
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        goto done;
    inf.t_halo = asp_time_now() - t; /* the radii; the exchange is added to it */
    if ((rc = halo_and_neighbourhoods(&r, &inf, err)) != 0)
        goto done;
    asp_free(&d->ctx, r.radius); /* the halo is closed */
    r.radius = NULL;
    inf.halo_points = (size_t)asp__dist_sum(d, r.pts.n_ghost);
    if ((rc = local_stages(&r, &inf, err)) != 0)
        goto done;
    t = asp_time_now();
    rc = asp__dist_build_hierarchy(d, &r.pts, &r.a, r.f, r.cls, &r.desc, &r.h, err);
    if ((rc = asp__dist_agree(d, rc, err)) != 0)
        goto done;
    asp_amg_csr_destroy(r.f);
    r.f = NULL;
    inf.amg.t_amg = asp_time_now() - t;
    inf.amg.repaired_rows = r.h.repaired;
    inf.amg.epsilon = r.desc.epsilon;
    inf.amg.k_min = r.desc.k_min;
    inf.amg.k_max = r.desc.k_max;
    inf.amg.fan_k = r.desc.fan_k;
    inf.nlevels = r.h.nlevels;
    t = asp_time_now();
    if (figures && (rc = asp__dist_basis_figures(d, &r.pts, &r.h, &r.desc, tau, &inf, err)) != 0)
        goto done;
    for (size_t l = 0; !figures && l < r.h.nlevels; l++)
        inf.level[l].unknowns = r.h.sizes[l];
    inf.t_stats = asp_time_now() - t;
    t = asp_time_now();
    if (out_path) {
        asp__dist_result res = {.pts = &r.pts, .tangent = r.tangent, .classifier = r.cls, .desc = &r.desc,
                                .nlevels = r.h.nlevels, .level_size = r.h.sizes, .prolong = r.h.p};
        frame_of(d, &r.pts, &res.frame);
        if ((rc = asp__dist_write_amg(d, &res, out_path, err)) != 0)
            goto done;
    }
    inf.t_write = asp_time_now() - t;
    inf.t_total = asp_time_now() - t0;
    double rss = peak_rss_mb();
    MPI_Allreduce(&rss, &inf.peak_rss_max_mb, 1, MPI_DOUBLE, MPI_MAX, d->comm);
    MPI_Allreduce(&rss, &inf.peak_rss_mean_mb, 1, MPI_DOUBLE, MPI_SUM, d->comm);
    inf.peak_rss_mean_mb /= d->size;
    /* every rank reports rank 0's stage times */
    MPI_Bcast(&inf.amg, (int)sizeof inf.amg, MPI_BYTE, 0, d->comm);
    if (info)
        *info = inf;
done:
    if (rc && info) {
        memset(info, 0, sizeof *info);
        info->rank = inf.rank;
        info->ranks = inf.ranks;
    }
    run_release(&r);
    return rc;
}
#endif
