/*
 * The multiscale decomposition (journal 2.1-2.3) on MPI ranks with hypre's
 * distributed BoomerAMG (issue 19): each rank reads its own range of a binary
 * PLY, the points are re-distributed along a Morton curve, neighbourhoods
 * cross rank borders through a halo, and the hierarchy, basis statistics and
 * the .amg file are produced without gathering the point set on one rank.
 */
#ifndef AMGSPLAT_AMG_DISTRIBUTED_H
#define AMGSPLAT_AMG_DISTRIBUTED_H

#include "amg.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { ASP_AMG_DIST_MAX_LEVELS = 100 };

/** tau for asp_amg_decompose_distributed when no level figures are wanted (only the level sizes). */
#define ASP_AMG_DIST_NO_FIGURES (-1.0)

/** Agreement figures of one level (journal eq. 8, thesis eq. 2.5), over every rank's points. */
typedef struct asp_amg_dist_level {
    size_t unknowns;
    size_t domains;          /* basis functions with Psi > tau somewhere */
    size_t strict_domains;   /* basis functions that are the argmax of Psi somewhere */
    size_t points_outside;   /* points with no Psi > tau (in no thresholded domain) */
    double max_pou_error;    /* max |sum_i Psi_i(x) - 1| */
    double mean_domains_per_point;
} asp_amg_dist_level;

/** What a distributed run did; identical on every rank except rank and the rank's own figures. */
typedef struct asp_amg_dist_info {
    int rank, ranks;
    size_t points;
    size_t own_points_min, own_points_max; /* points owned per rank after the Morton re-distribution */
    size_t halo_points;                    /* copies received from other ranks, all ranks together */
    size_t nlevels;
    asp_amg_dist_level level[ASP_AMG_DIST_MAX_LEVELS];
    asp_amg_info amg;                      /* as asp_amg_get_info; the t_* fields are rank 0's */
    double t_read, t_halo, t_write, t_stats, t_total;
    double peak_rss_max_mb, peak_rss_mean_mb; /* per rank (getrusage), at the end of the run */
} asp_amg_dist_info;

/**
 * Number of ranks of the MPI job this process was started in, read from the
 * launcher's environment (Open MPI, MPICH, Slurm) without starting MPI; 1
 * outside mpirun. Thread-safe.
 */
int asp_amg_mpi_ranks(void);

/**
 * Decomposes the binary PLY in_path (little-endian; vertex element first, with
 * x y z as float or double and optionally nx ny nz, red green blue [alpha]
 * uchar, radius, label) on every rank of MPI_COMM_WORLD, collectively: every
 * rank must call it with the same arguments. Starts MPI and hypre when
 * nobody did (asp_amg_distributed_shutdown ends them). With out_path the
 * result is written as a version-3 .amg file that asp_amg_load reads as a
 * serial one, with the points in Morton order (not the input order). tau is
 * the domain threshold of the level figures in info (0.05 in the journal);
 * ASP_AMG_DIST_NO_FIGURES skips them (the basis of every level, about a sixth
 * of the time at 1M points), and info->level then holds only the unknowns.
 * Returns the same code on every rank: 0, ASP_EIO, ASP_EFORMAT (not a binary
 * little-endian PLY with x y z), ASP_EINVAL, ASP_EDEGENERATE, ASP_ENOMEM,
 * ASP_ESOLVER, ASP_EUNSUPPORTED (built without hypre); err holds the first
 * failing rank's message. Not thread-safe (MPI and hypre are process-wide).
 */
int asp_amg_decompose_distributed(const char *in_path, const char *out_path, const asp_amg_desc *desc, double tau,
                                  const asp_context *ctx, asp_amg_dist_info *info, asp_error *err);

/** Finalises hypre and MPI if asp_amg_decompose_distributed started them. Idempotent. */
void asp_amg_distributed_shutdown(void);

#ifdef __cplusplus
}
#endif
#endif
