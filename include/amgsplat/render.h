/*
 * amgsplat render module: OpenGL 4.5 core rendering of point sets as opaque
 * oriented discs (journal section 1: "simple point primitives, such as flat
 * discs ... position, radius, color, and normal"; Pajarola et al. 2003 section
 * 5: surfels drawn as polygons in their tangent plane, shaped per fragment).
 * Headless through EGL (Mesa llvmpipe or a GPU), windowed through GLFW.
 *
 * Threading: a GL context belongs to one thread at a time. Every function that
 * takes an asp_gl_context (or an asp_renderer made from one) must be called
 * from the thread that created it; different contexts may be used from
 * different threads concurrently. The camera (camera.h) is pure math and
 * thread safe.
 */
#ifndef AMGSPLAT_RENDER_H
#define AMGSPLAT_RENDER_H

#include "camera.h"
#include "cloud.h"
#include "hier.h"
#include "image.h"
#include "prim.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------ */
/* GL context                                                               */
/* ------------------------------------------------------------------------ */

/** An OpenGL 4.5 core context, headless (EGL) or in a window (GLFW). Opaque. */
typedef struct asp_gl_context asp_gl_context;

/** Flags for asp_gl_context_desc.flags; 0 is the safe default. */
enum asp_gl_context_flags {
    /* Ask for a debug context: the driver validates more and reports more
     * through KHR_debug, at some speed cost. Errors are collected either way. */
    ASP_GL_CONTEXT_DEBUG = 1 << 0,
    /* Headless only: prefer Mesa's software rasteriser (llvmpipe) even when a
     * GPU is present, e.g. for reproducible images across machines. */
    ASP_GL_CONTEXT_SOFTWARE = 1 << 1
};

/** Options for creating a GL context; the zero value means defaults. */
typedef struct asp_gl_context_desc {
    unsigned flags;           /* asp_gl_context_flags */
    uint32_t width, height;   /* window only: client area in screen units; 0 = 1280 x 800 */
    const char *title;        /* window only: title; NULL = "amgsplat" */
} asp_gl_context_desc;

/**
 * Creates a headless OpenGL 4.5 core context without any window or pbuffer
 * (EGL_KHR_surfaceless_context; renders go to an offscreen framebuffer) and
 * makes it current on the calling thread. Displays are tried in this order:
 * EGL devices that are not software (EGL_EXT_platform_device; the GPU on an
 * NVIDIA machine), Mesa's surfaceless platform (llvmpipe when there is no GPU),
 * software EGL devices, and eglGetDisplay(EGL_DEFAULT_DISPLAY); with
 * ASP_GL_CONTEXT_SOFTWARE, software displays come first. desc may be NULL;
 * ctx (NULL = C library) is the allocator of the context's CPU-side memory.
 *
 * On success *out owns the context (free with asp_gl_context_destroy). On
 * failure returns ASP_EGL with "no OpenGL 4.5 context: ..." naming each display
 * tried and its EGL error (e.g. EGL_NOT_INITIALIZED), or ASP_ENOMEM; *out is
 * unchanged. Nothing process-wide is changed (no environment variables).
 */
int asp_gl_context_create_headless(const asp_gl_context_desc *desc, const asp_context *ctx, asp_gl_context **out,
                                  asp_error *err);

/**
 * Creates a window of desc->width x desc->height with an OpenGL 4.5 core
 * context through GLFW and makes it current. GLFW keeps process-wide state:
 * call from the main thread and keep at most one window context alive at a time
 * (destroying it terminates GLFW). Returns 0, ASP_EGL ("no OpenGL 4.5 window:
 * ..." with GLFW's reason, e.g. no display) or ASP_ENOMEM; *out is unchanged on
 * failure.
 */
int asp_gl_context_create_window(const asp_gl_context_desc *desc, const asp_context *ctx, asp_gl_context **out,
                                asp_error *err);

/**
 * Destroys the context and every GL object it still owns (the offscreen
 * framebuffer); renderers made from it must be destroyed first. NULL is
 * accepted. The EGL display is left initialised: it is shared by every
 * context of the process, and eglTerminate would invalidate the others.
 */
void asp_gl_context_destroy(asp_gl_context *gl);

/** Makes gl current on the calling thread. Returns 0 or ASP_EGL. */
int asp_gl_context_make_current(asp_gl_context *gl, asp_error *err);

/**
 * Reports GL errors collected since the last check: KHR_debug messages of type
 * error (the first message is kept, with a count) and glGetError codes.
 * Returns 0, or ASP_EGL with "cannot render: GL_INVALID_ENUM: <driver message>"
 * and clears the collected errors. Only for callers issuing their own GL calls:
 * every library function checks after its own GL work.
 */
int asp_gl_context_check(asp_gl_context *gl, asp_error *err);

/** GL_RENDERER of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"; valid until destroy. */
const char *asp_gl_context_renderer(const asp_gl_context *gl);
/** GL_VERSION of the context, e.g. "4.5 (Core Profile) Mesa 22.3.6"; valid until destroy. */
const char *asp_gl_context_version(const asp_gl_context *gl);
/** How the context was made: "egl-device", "egl-surfaceless", "egl-default" or "glfw". */
const char *asp_gl_context_backend(const asp_gl_context *gl);

/** Window contexts: swaps the front and back buffers. No-op for headless contexts. */
void asp_gl_context_swap_buffers(asp_gl_context *gl);
/** Window contexts: processes pending window events. No-op for headless contexts. */
void asp_gl_context_poll_events(asp_gl_context *gl);
/** Window contexts: 1 once the user asked to close the window; always 0 for headless contexts. */
int asp_gl_context_should_close(const asp_gl_context *gl);
/** Window contexts: framebuffer size in pixels; 0 x 0 for headless contexts. */
void asp_gl_context_framebuffer_size(const asp_gl_context *gl, uint32_t *width, uint32_t *height);

/**
 * Window contexts: the GLFWwindow * (as void *) for an application that
 * handles the window's input itself (the viewer); NULL for headless contexts.
 * Valid until asp_gl_context_destroy.
 */
void *asp_gl_context_window(const asp_gl_context *gl);

/**
 * Window contexts: reads what the last frame drew into the back buffer (call
 * before asp_gl_context_swap_buffers) into *out (zeroed or released; RGBA8,
 * rows top first, the stored sRGB bytes, alpha 255). Returns 0;
 * ASP_EUNSUPPORTED (a headless context: use asp_render_to_image); ASP_EINVAL
 * (a minimised window); ASP_EGL; ASP_ENOMEM. *out is unchanged on failure.
 */
int asp_gl_context_read_window(asp_gl_context *gl, asp_image *out, asp_error *err);

/* The orbit camera (asp_camera, asp_camera_*) is GL-free: camera.h, included above. */

/* ------------------------------------------------------------------------ */
/* Renderers                                                                */
/* ------------------------------------------------------------------------ */

/**
 * A point set uploaded to GL with a way of drawing it (discs today; splats,
 * squares and domain primitives later). Opaque; drawn with
 * asp_render_to_image. Keeps a reference to the asp_gl_context it was created
 * with, which must outlive it.
 */
typedef struct asp_renderer asp_renderer;

/**
 * Eye-dome lighting (Boucheny 2009; src/render/edl.c), a screen-space pass of
 * the disc and square renderers for points without normals: each pixel is
 * darkened by exp(-300 strength m), m the mean over 8 neighbours radius
 * pixels away of how much nearer they are in log2 depth, so silhouettes and
 * depth steps get dark rims and surfaces turning away shade. Drawn through a
 * single-sample target of the frame's size (so multisampling does not apply
 * to the points while it is on). The zero value is off.
 */
typedef struct asp_edl_desc {
    float strength;            /* 0 = off; 1 = the usual (CloudCompare's and Potree's default look) */
    float radius;              /* neighbour distance in pixels, 0..16; 0 = 1.4 */
} asp_edl_desc;

/** Options of the disc renderer; the zero value means defaults. */
typedef struct asp_disc_renderer_desc {
    float radius_scale;        /* multiplies every disc radius; 0 = 1 */
    uint8_t default_color[4];  /* sRGB colour of points when the cloud has none; all 0 = light grey 200,200,200 */
    const float *clip_planes;  /* 8 floats per point (asp_crease_clip_planes in geom.h), NULL = none;
                                  only read during create */
    asp_edl_desc edl;          /* eye-dome lighting; zero = off */
} asp_disc_renderer_desc;

/**
 * Uploads cloud to GL buffers and returns a renderer drawing each point as an
 * opaque disc of its radius in its tangent plane: one triangle around the disc
 * in object space (so depth is exact and discs occlude correctly), with the
 * fragments outside the disc discarded. Missing attributes:
 *  - normals: each disc faces the eye;
 *  - radii: one radius for all, asp_render_default_radius(cloud);
 *  - colours: desc->default_color (light grey).
 * With desc->clip_planes, the disc of point i keeps only the samples x (in
 * the cloud's local frame) with n . x + d >= 0 for both of its planes
 * (clip_planes[8 i .. 8 i + 7] = two (nx, ny, nz, d); four zeros = no clip),
 * so discs end at sharp creases (Botsch et al. 2005 clip lines); the test is
 * per sample, like the disc test, so multisampled edges stay exact.
 * Positions are used relative to cloud->origin (the renderer works in the
 * cloud's local frame; put the camera there too). cloud is only read during
 * the call. Makes gl current.
 * Returns 0; ASP_EDEGENERATE for an empty cloud or when radii are missing and
 * cannot be estimated (all points equal); ASP_EFORMAT if a position, normal,
 * radius or clip plane value is not finite (names the point);
 * ASP_EUNSUPPORTED for more than 2^31-1 points; ASP_EGL (out of GPU memory,
 * shader failure); ASP_ENOMEM.
 * *out is unchanged on failure; free the result with asp_renderer_destroy.
 */
int asp_disc_renderer_create(asp_gl_context *gl, const asp_cloud *cloud, const asp_disc_renderer_desc *desc,
                             asp_renderer **out, asp_error *err);

/** Frees the renderer's GL buffers and memory (makes its context current). NULL is accepted. */
void asp_renderer_destroy(asp_renderer *r);

/** Short name of the renderer kind ("disc"). */
const char *asp_renderer_name(const asp_renderer *r);

/** Number of points (primitives) the renderer draws. */
size_t asp_renderer_count(const asp_renderer *r);

/** Flags for asp_render_desc.flags. */
enum asp_render_flags {
    ASP_RENDER_UNLIT = 1 << 0, /* output the point colours without shading */
    ASP_RENDER_WAIT = 1 << 1   /* asp_render_frame: wait until the GPU has finished (glFinish), for timing */
};

/** How to render one image; the zero value means defaults. */
typedef struct asp_render_desc {
    uint32_t width, height;     /* pixels; 0 = 512 */
    uint8_t background[4];      /* sRGB RGBA, straight alpha; zero = transparent black */
    uint32_t samples;           /* multisampling per pixel; 0 or 1 = none; capped at GL_MAX_SAMPLES */
    float light_azimuth;        /* degrees, light direction relative to the view: 0, 0 = headlight */
    float light_elevation;      /* degrees; positive = light from above the view direction */
    unsigned flags;             /* asp_render_flags */
} asp_render_desc;

/**
 * Renders r seen by cam into *out (width x height RGBA8, rows top first, sRGB,
 * straight alpha). Shading is in linear light: colour * (0.25 + 0.75 |n . l|)
 * with a directional light l fixed to the camera (two-sided Lambert; 0.25 is
 * the ambient term), stored to an sRGB framebuffer, so a surface facing the
 * light shows exactly its colour. Pixels no disc covers get the background.
 * cam->aspect is used as given; set it to width / height to avoid stretching.
 *
 * out must be zeroed or released; on success it is initialised here (release
 * with asp_image_release); on failure it is unchanged. gl must be the context
 * r was created with. Returns 0, ASP_EINVAL (size over 16384, or the GL limit),
 * ASP_EGL (GL errors, framebuffer incomplete) or ASP_ENOMEM.
 */
int asp_render_to_image(asp_gl_context *gl, asp_renderer *r, const asp_camera *cam, const asp_render_desc *desc,
                        asp_image *out, asp_error *err);

/**
 * Draws r seen by cam without reading anything back: into the window's back
 * buffer for a window context (desc->width/height 0 = the framebuffer size;
 * show it with asp_gl_context_swap_buffers), or into the headless context's
 * offscreen target (then asp_render_to_image is what you want, except for
 * timing the drawing alone with ASP_RENDER_WAIT). Same shading, background and
 * errors as asp_render_to_image. A window framebuffer that is not sRGB-capable
 * shows linear colours (darker mid-tones).
 */
int asp_render_frame(asp_gl_context *gl, asp_renderer *r, const asp_camera *cam, const asp_render_desc *desc,
                     asp_error *err);

/**
 * The disc radius used when a cloud has no radii: 2 * sqrt(A / (pi n)) where
 * A = xy + yz + zx of the bounding box sides (half the box's surface area:
 * exact for a plane, 0.95 of a sphere's area) and n the point count. Discs of
 * radius sqrt(A / (pi n)) would have the surface's total area; the factor 2
 * closes the gaps of irregular (random) sampling. If A is 0 (colinear points)
 * the longest side / n is used. Returns 0 for an empty cloud or all points
 * equal.
 */
float asp_render_default_radius(const asp_cloud *cloud);

/**
 * Bounding sphere of what a disc renderer draws, in the cloud's local frame:
 * center = middle of the position bounds, radius = the largest distance from
 * it plus the largest disc radius (the cloud's radii, or
 * asp_render_default_radius). Returns 0, or ASP_EDEGENERATE (empty cloud, or a
 * zero radius: all points equal without radii) or ASP_EFORMAT (non-finite
 * values); outputs are unchanged on failure.
 */
int asp_render_bounding_sphere(const asp_cloud *cloud, float center[3], float *radius, asp_error *err);

/* ------------------------------------------------------------------------ */
/* Splat and square renderers on the point hierarchy (hier.h)               */
/* ------------------------------------------------------------------------ */

/** How the splat renderer lights its splats (asp_splat_renderer_desc.lighting). */
typedef enum asp_splat_lighting {
    /* Seed 001 section 5.2, Fig. 14: each splat triangle is lit at its three
     * corners, whose normals are the splat normal tilted outwards by the
     * node's normal-cone semi-angle (at most 60 degrees; 0 for input points),
     * and the shade is interpolated across it (Gouraud). */
    ASP_SPLAT_LIGHT_GOURAUD = 0,
    /* The same corner normals interpolated per fragment, blended with the
     * kernel like the colours, normalised and lit per pixel in the resolve
     * pass (smooth across splats, one extra float target). */
    ASP_SPLAT_LIGHT_PIXEL = 1,
    /* One shade per splat from its normal. */
    ASP_SPLAT_LIGHT_FLAT = 2
} asp_splat_lighting;

/** How splats are combined (asp_splat_renderer_desc.mode). */
typedef enum asp_splat_mode {
    /* Seed 001 section 5: epsilon-z-buffer visibility pass, additive blending
     * of (psi * colour, psi), per-pixel normalisation. */
    ASP_SPLAT_BLEND = 0,
    /* Opaque ellipses with an exact depth test, no blending (QSplat-like, the
     * cheap mode: one pass). */
    ASP_SPLAT_OPAQUE = 1
} asp_splat_mode;

/** Flags for asp_splat_renderer_desc.flags and asp_square_renderer_desc.flags. */
enum asp_splat_renderer_flags {
    /* Drop subtrees whose normal cone faces away from the eye (seed 004
     * 3.2.2). Off by default: points whose normal faces slightly away can
     * still cover silhouette pixels. Ignored for unoriented hierarchies. */
    ASP_SPLAT_CULL_BACKFACES = 1 << 0,
    /* Seed 001 Fig. 11 / eq. 12 as written: the ellipse rim is the kernel's r = b, so psi_E(rim) =
     * exp(-a) (0.0025 for a = 6) and b cancels out. Default: rim at r = 1 (see the desc). */
    ASP_SPLAT_KERNEL_RIM_AT_B = 1 << 1,
    /* Seed 001 section 5.3 as written: one depth offset epsilon for every splat, in world units of the
     * cloud's local frame, instead of epsilon times each splat's major semi-axis. */
    ASP_SPLAT_EPSILON_UNIFORM = 1 << 2
};

/** Blending kernel shape (asp_splat_renderer_desc.kernel). */
typedef enum asp_splat_kernel {
    ASP_SPLAT_KERNEL_PSI_E = 0, /* seed 001 eq. 12: exp(-a (r / b)^n) */
    ASP_SPLAT_KERNEL_PSI_G = 1  /* seed 001 eq. 11: exp(-r^2 / (2 sigma^2)), cut at the ellipse rim */
} asp_splat_kernel;

/**
 * Options of the splat renderer; the zero value means defaults.
 *
 * Kernel (seed 001 eq. 12): psi_E(r) = exp(-a (r / b)^n) where r is the
 * position in the splat's ellipse in units of its semi-axes (r = 1 on the
 * ellipse e_i, Fig. 11 with the axes as unit), cut off at r = min(b, 1): the
 * ellipse is the splat's support (section 4.1) and b the kernel's own support
 * radius as in Fig. 10. Deviation: Fig. 11 maps the ellipse rim to r = b, where
 * b cancels out; b = 1 gives exactly that kernel, exp(-a r^n). With the
 * defaults a = 6, b = 1.5, n = 3 (Fig. 18 b) the weight is 1 at the centre,
 * 0.5 at r = 0.73 and 0.17 on the rim. ASP_SPLAT_KERNEL_RIM_AT_B gives the seed's
 * mapping (rim at r = b, weight exp(-a) there); kernel = ASP_SPLAT_KERNEL_PSI_G the
 * Gaussian of eq. 11 in the same r (sigma 0 = 0.5: weight 0.135 on the rim).
 * asp_splat_kernel_weight evaluates the weight the blend pass uses.
 */
typedef struct asp_splat_renderer_desc {
    float kernel_a;          /* width: larger = narrower kernel; 0 = 6; else > 0 */
    float kernel_b;          /* support radius in ellipse units; 0 = 1.5; else > 0 */
    float kernel_n;          /* drop-off sharpness; 0 = 3; else > 0 */
    float epsilon;           /* depth offset of the visibility pass (section 5.3, Fig. 15), along each
                                eye ray, in units of each splat's major semi-axis; 0 = 1; < 0 = none.
                                With ASP_SPLAT_EPSILON_UNIFORM: in world units, 0 = the mean major
                                semi-axis of the point splats */
    float tolerance;         /* tau in pixels (asp_hier_view.tau): splats whose projected ellipse is smaller
                                are drawn instead of their children; 0 = every visible input point */
    float radius_scale;      /* multiplies every ellipse; 0 = 1 */
    asp_splat_lighting lighting;
    asp_splat_mode mode;
    unsigned flags;          /* asp_splat_renderer_flags */
    uint8_t default_color[4]; /* sRGB colour when the cloud has no colours; all 0 = light grey 200,200,200 */
    asp_hier_desc hier;      /* hierarchy build options for asp_splat_renderer_create */
    const float *clip_planes; /* 8 floats per INPUT point, by input point index (asp_crease_clip_planes in
                                 geom.h), NULL = none; only read during create */
    asp_splat_kernel kernel;  /* 0 = PSI_E */
    float kernel_sigma;       /* PSI_G: sigma in the kernel's r; 0 = 0.5; else > 0 */
} asp_splat_renderer_desc;

/**
 * The blending weight the splat renderer's blend pass gives a fragment at
 * ellipse radius r (r = 1 on the ellipse rim, in units of the semi-axes)
 * with the kernel options of desc (NULL = defaults): psi_E or psi_G of the
 * kernel radius (r, or b r with ASP_SPLAT_KERNEL_RIM_AT_B), r clamped to the
 * support. Negative or non-finite options give NaN. Thread-safe, no GL.
 */
float asp_splat_kernel_weight(const asp_splat_renderer_desc *desc, float r);

/**
 * Seed 001 section 5.1 gives the screen tolerance tau "in percent of the
 * window area": the pixel tolerance (asp_splat_renderer_desc.tolerance, a
 * projected size) of a splat whose projected disc covers percent % of a
 * width x height window, 2 sqrt(A / pi) with A = percent / 100 * width *
 * height. Returns 0 for percent <= 0 or a non-finite value.
 */
float asp_render_tolerance_from_area(double percent, uint32_t width, uint32_t height);

/**
 * Builds the point hierarchy of cloud (asp_hier_build with desc->hier; the
 * renderer owns it) and returns a renderer drawing, per frame, the
 * view-dependent cut of the hierarchy for tau = desc->tolerance pixels (seed
 * 001 section 5.1 step 1; ctx: threads and allocator of the build, NULL =
 * defaults) as elliptical splats blended with the kernel
 * psi_E (see asp_splat_renderer_desc): pass 1 writes the depth of the splats
 * pushed back by epsilon along the eye rays, pass 2 adds (psi * colour, psi)
 * of every splat within epsilon of the front surface into a float target,
 * pass 3 divides by the weight (section 5.4) and writes the sRGB colour, with
 * the background where no splat lies. Shading as asp_render_to_image (colour
 * * (0.25 + 0.75 |n . l|), ASP_RENDER_UNLIT), with desc->lighting. Positions
 * are in the cloud's local frame, as for the disc renderer; cloud is only read
 * during the call. asp_renderer_count gives the splats drawn in the last
 * frame (before the first frame: the number of input points). Makes gl current.
 * With desc->clip_planes, the splat of input point i keeps only the samples x
 * (local frame) with n . x + d >= 0 for both planes of clip_planes[8 i ..
 * 8 i + 7] (four zeros = no clip), in the depth pass and the blend pass (and
 * in opaque mode), so splats end at sharp creases (Botsch et al. 2005 clip
 * lines); node splats of coarser cuts (tolerance > 0) are never clipped.
 * Returns 0; ASP_EINVAL (a negative or non-finite option); ASP_EFORMAT (a
 * non-finite clip plane value, naming the point); the errors of
 * asp_hier_build (ASP_EDEGENERATE for an empty cloud, ASP_EINVAL for
 * non-finite values); ASP_EUNSUPPORTED (more than 2^31 - 1 splats); ASP_EGL;
 * ASP_ENOMEM. *out is unchanged on failure; free it with asp_renderer_destroy.
 */
int asp_splat_renderer_create(asp_gl_context *gl, const asp_cloud *cloud, const asp_splat_renderer_desc *desc,
                              const asp_context *ctx, asp_renderer **out, asp_error *err);

/**
 * Like asp_splat_renderer_create on an existing hierarchy, which the renderer
 * keeps a reference to: hier must outlive it (desc->hier is not used). Colours come from the splats when the hierarchy has them
 * (ASP_HIER_HAS_COLORS), else desc->default_color. desc->clip_planes, if
 * given, holds 8 * asp_hier_point_count(hier) floats indexed by the input
 * point index of the hierarchy's source cloud (asp_hier_splat.index).
 */
int asp_splat_renderer_create_hier(asp_gl_context *gl, const asp_hier *hier, const asp_splat_renderer_desc *desc,
                                   asp_renderer **out, asp_error *err);

/** Options of the square renderer; the zero value means defaults. */
typedef struct asp_square_renderer_desc {
    float point_size;        /* side of every square in pixels; 0 = each splat's projected ellipse diameter
                                (2 a, so the square covers the ellipse); at most the GL point size limit */
    float tolerance;         /* tau in pixels, as asp_splat_renderer_desc.tolerance */
    float radius_scale;      /* multiplies the projected size; 0 = 1 */
    unsigned flags;          /* asp_splat_renderer_flags */
    uint8_t default_color[4]; /* as asp_splat_renderer_desc */
    asp_hier_desc hier;      /* hierarchy build options for asp_square_renderer_create */
    asp_edl_desc edl;        /* eye-dome lighting (as asp_disc_renderer_desc.edl); zero = off */
} asp_square_renderer_desc;

/**
 * Builds the hierarchy of cloud (owned by the renderer) and returns a renderer
 * drawing each splat of the per-frame cut as one opaque, depth-tested,
 * screen-aligned square of the GL point primitive (seed 004 3.2.6, the
 * "rectangular point-representations used by graphics hardware"), flat-shaded
 * by the splat normal, sized by its projected ellipse (seed 004 3.2.3) or
 * desc->point_size. The cheapest mode: one vertex per splat, no per-fragment
 * work. Same frame, count and errors as asp_splat_renderer_create.
 */
int asp_square_renderer_create(asp_gl_context *gl, const asp_cloud *cloud, const asp_square_renderer_desc *desc,
                               const asp_context *ctx, asp_renderer **out, asp_error *err);

/** Like asp_square_renderer_create on an existing hierarchy, which must outlive the renderer. */
int asp_square_renderer_create_hier(asp_gl_context *gl, const asp_hier *hier, const asp_square_renderer_desc *desc,
                                    asp_renderer **out, asp_error *err);

/**
 * Sets the screen tolerance tau (pixels, >= 0) and the depth limit (0 = none;
 * see asp_hier_view.depth_limit) of a splat or square renderer for the
 * following frames, e.g. from asp_hier_adapt. Returns 0; ASP_EINVAL for a
 * negative or NaN tau; ASP_EUNSUPPORTED for a renderer without a hierarchy
 * (disc), naming it. No GL calls; same thread rules as the renderer.
 */
int asp_renderer_set_lod(asp_renderer *r, float tolerance, uint32_t depth_limit, asp_error *err);

/**
 * Cuts a splat or square renderer's hierarchy to at most splats splats per
 * frame (0 = off: tau and the depth limit decide again): the splats of
 * largest projected size are refined first (asp_hier_select_count), so the
 * count is exact unless the tree's fan-out prevents it (at most 7 fewer with
 * leaves of 8), or fewer points are visible. This is the cut of thesis Fig. 1.1,
 * points against the same number of domain primitives (amgsplat eval), and a
 * fixed budget for weak hardware. Returns 0; ASP_EUNSUPPORTED for a renderer
 * without a hierarchy (disc), naming it. No GL calls; same thread rules as the
 * renderer.
 */
int asp_renderer_set_budget(asp_renderer *r, size_t splats, asp_error *err);

/** Figures of a renderer's last frame (asp_renderer_stats). */
typedef struct asp_renderer_stats {
    size_t count;          /* primitives drawn in the last frame (= asp_renderer_count) */
    size_t points;         /* input points (the leaves' points) */
    size_t nodes;          /* hierarchy nodes; 0 for renderers without one */
    float tolerance;       /* tau of the last frame; 0 without a hierarchy */
    uint32_t depth_limit;  /* depth limit of the last frame; 0 = none */
    size_t budget;         /* splat budget (asp_renderer_set_budget); 0 = none, tau decides */
    double select_seconds; /* CPU time of the last cut (asp_hier_select) and its upload */
} asp_renderer_stats;

/** Fills *out for any renderer (disc: count = points, the rest 0). Thread rules of the renderer. */
void asp_renderer_stats_get(const asp_renderer *r, asp_renderer_stats *out);

/**
 * Which way the compute renderer (renderer table row "compute", issue 28) draws: "opaque-atomic64"
 * (one 64-bit atomicMin pass, GL_NV_shader_atomic_int64), "opaque-atomic32" (32-bit depth then
 * colour), "blend-atomic32" (seed 001's blended splats); NULL for any other renderer.
 */
const char *asp_compute_renderer_path(const asp_renderer *r);

/* ------------------------------------------------------------------------ */
/* Frame budget: the tolerance that holds a frame time (issue 18 item 5)    */
/* ------------------------------------------------------------------------ */

/**
 * Options of a frame budget; the zero value means defaults except target_ms.
 * The controller works on log tau: a frame of f ms gives the error
 * e = ln(f / T), ignored within the dead band, and tau is multiplied by
 * exp(gain * e) (integral control, damped by gain < 1 and clamped to a factor
 * max_step per frame), so tau settles where the frame time is T whatever the
 * renderer's cost per splat. Below tolerance_min it stops (the finest cut
 * fits); at tolerance_max, still too slow, it lowers the traversal depth limit
 * one level per settled step (seed 004 section 3.2.5's adaptive traversal
 * depth, Fig. 3.5) and raises it again before refining tau.
 *
 * Coarser is not always faster: blended splats cost fill, and a coarse cut's
 * splats are large, so close up a cut of 2,000 splats takes as long as one of
 * 7,000 (llvmpipe, 800x600). The controller measures the response of every
 * move that changed the count drawn by more than 10% (slope = -d ln f /
 * d ln tau, a depth step counting as 1; a move that changed nothing, e.g.
 * below the leaves' size, says nothing about the cost, and the next move in
 * that direction takes the largest step) and, while
 * too slow with a slope under 0.2, stops coarsening ("bound": the floor of
 * this view is above T) instead of trading the picture for nothing; every
 * 8th such frame it probes one step coarser, kept if it helped and undone
 * if not, so a new view is noticed and the picture never creeps to blobs.
 * Nor does it coarsen below min_count primitives: there it is saturated.
 */
typedef struct asp_frame_budget_desc {
    double target_ms;     /* T, the frame time to hold, ms; > 0 and finite (required) */
    float tolerance;      /* tau of the first frame, pixels; 0 = 4 (coarse: a slow first frame costs most) */
    float tolerance_min;  /* 0 = 0.25 px (every splat larger than a quarter pixel is refined: full detail) */
    float tolerance_max;  /* 0 = 256 px */
    float gain;           /* ln tau per unit of ln(f / T), in (0, 1]; 0 = 0.35 (frame time falls ~1.1-2.2 times
                             as fast as tau rises on llvmpipe, so the loop gain stays below 1: no overshoot) */
    float deadband;       /* |ln(f / T)| below this leaves tau alone; 0 = 0.05, < 0 = none */
    float max_step;       /* largest factor tau may change by in one frame, > 1; 0 = 2 */
    uint32_t depth_max;   /* the depth limit that means "no limit" (asp_hier_depth + 1); 0 = no depth fallback */
    size_t min_count;     /* no coarser cut than about this many primitives (a cut's count goes as tau^-2, a
                             depth step divides it by up to 8): below ~1000 splats a model is blobs, as slow
                             as it may be; 0 = 1000; 1 = none (seed 004 Fig. 3.5 goes down to depth 1) */
} asp_frame_budget_desc;

/** State of a frame budget; read its fields, change them only through the functions. */
typedef struct asp_frame_budget {
    asp_frame_budget_desc desc; /* resolved options */
    float tolerance;            /* tau for the next frame, pixels */
    uint32_t depth_limit;       /* depth limit for the next frame; 0 = none */
    double last_ms;             /* the last frame time fed */
    size_t frames;              /* frame times fed */
    uint32_t hold;              /* frames left before the depth limit may move again */
    int saturated;              /* coarsest setting reached and the last frame still over budget */
    int finest;                 /* finest setting reached and the last frame under budget */
    int bound;                  /* over budget, but coarser settings stopped making frames faster */
    float slope;                /* measured -d ln(frame time) / d ln tau (EMA over moves); starts at 1 */
    double last_log_ms;         /* ln of the last frame time */
    double last_move;           /* the move applied before the next frame: ln tau, or +-1 per depth step */
    size_t last_count;          /* primitives drawn in the last frame (0 = not told) */
    double prev_move;           /* the move before the last frame (a sign for the next step) */
    uint32_t since_probe;       /* bound frames since the last probing step */
    int probing;                /* the last move was a probe: undone if it did not help */
    float probe_tau;            /* where the probe started */
    uint32_t probe_depth;
} asp_frame_budget;

/**
 * Initialises b from desc. Returns 0 or ASP_EINVAL naming the bad option
 * (target_ms not > 0, a range with min > max, gain outside (0, 1], max_step
 * <= 1, a non-finite value); b is unchanged on failure. No GL; thread safe
 * on distinct b.
 */
int asp_frame_budget_init(asp_frame_budget *b, const asp_frame_budget_desc *desc, asp_error *err);

/**
 * Feeds the time of the frame just drawn (ms, everything the user waits for)
 * and the primitives it drew (asp_renderer_count; 0 = unknown), and computes
 * tau and the depth limit for the next one. A negative or non-finite time is
 * ignored. Returns 1 if tau or the depth limit changed, else 0.
 */
int asp_frame_budget_update(asp_frame_budget *b, double frame_ms, size_t count);

/**
 * asp_renderer_set_lod(r, b->tolerance, b->depth_limit): every renderer with
 * a level of detail (splat, square, and those implementing the set_lod hook)
 * follows the budget. Returns 0, or ASP_EUNSUPPORTED for a renderer without
 * one (disc, prim, mesh: the budget then has no effect).
 */
int asp_frame_budget_apply(const asp_frame_budget *b, asp_renderer *r, asp_error *err);

/** What asp_frame_budget_settle reached. */
typedef struct asp_frame_budget_result {
    size_t frames;         /* frames drawn */
    int settled;           /* 1: held T with tau steady, or the budget can do no better (finest or coarsest
                              setting, or bound: coarser is not faster) */
    int held;              /* the median of the last `window` frames is within max(10%, the dead band) of T */
    double median_ms;      /* median frame time of the last `window` frames */
    double p10_ms, p90_ms; /* their 10th and 90th percentiles */
    float tolerance;       /* tau reached */
    uint32_t depth_limit;  /* depth limit reached (0 = none) */
    size_t count;          /* primitives drawn in the last frame */
} asp_frame_budget_result;

/**
 * A simulated budget for offline renders (amgsplat render --frame-ms): draws
 * r seen by cam with desc (asp_render_frame with ASP_RENDER_WAIT, so each
 * frame's time is the drawing finished) up to max_frames times (0 = 200),
 * feeding b after every frame and applying it before the next, and stops
 * once the median of the last window frames (0 = 9) is within max(10%, the
 * dead band) of T and tau moved less than 10% over them, or the budget can
 * do no better (asp_frame_budget finest, saturated or bound). b keeps the reached
 * state, so the next view starts from it. Returns 0 and *out; the errors of
 * asp_frame_budget_apply and asp_render_frame; ASP_ENOMEM.
 */
int asp_frame_budget_settle(asp_gl_context *gl, asp_renderer *r, const asp_camera *cam,
                            const asp_render_desc *desc, asp_frame_budget *b, size_t max_frames, size_t window,
                            asp_frame_budget_result *out, asp_error *err);

/* ------------------------------------------------------------------------ */
/* Text over a frame (the viewer's figures)                                 */
/* ------------------------------------------------------------------------ */

/** Draws lines of text over what a frame drew. Opaque; made from a context, which must outlive it. */
typedef struct asp_text_overlay asp_text_overlay;

/** Where and how asp_text_overlay_draw writes; the zero value means defaults. */
typedef struct asp_text_overlay_desc {
    float x, y;           /* top-left corner of the text block, pixels from the target's top-left */
    float scale;          /* pixels per font unit (stb_easy_font's glyphs are ~7 units tall); 0 = 2 */
    uint8_t color[4];     /* sRGB text colour; all 0 = white */
    uint8_t box[4];       /* sRGB colour of the box behind the text, alpha blended; all 0 = black, alpha 160 */
    uint8_t fill[4];      /* sRGB colour the whole target is covered with first (a text screen); alpha 0 = none */
} asp_text_overlay_desc;

/** Width and height in pixels of the box asp_text_overlay_draw draws for text at scale (0 = 2). Pure. */
void asp_text_overlay_measure(const char *text, float scale, float *width, float *height);

/** Creates the overlay's GL program and buffers. Returns 0, ASP_EGL or ASP_ENOMEM; *out unchanged on failure. */
int asp_text_overlay_create(asp_gl_context *gl, asp_text_overlay **out, asp_error *err);

/**
 * Draws text ('\n' separates lines; stb_easy_font's ASCII glyphs) in a box
 * over the window's back buffer (window context; after asp_render_frame,
 * before asp_gl_context_read_window and the swap) or the headless context's
 * offscreen target, without depth test and without clearing. Returns 0,
 * ASP_EINVAL (text over 4096 characters), ASP_EGL or ASP_ENOMEM.
 */
int asp_text_overlay_draw(asp_text_overlay *o, const char *text, const asp_text_overlay_desc *desc,
                          asp_error *err);

/** Frees the overlay's GL objects (makes its context current). NULL is accepted. */
void asp_text_overlay_destroy(asp_text_overlay *o);

/* ------------------------------------------------------------------------ */
/* Domain primitives (prim.h levels): journal section 4, thesis chapter 4   */
/* ------------------------------------------------------------------------ */

/**
 * How the textured domain primitives of a .dps level are blended back into a
 * surface (asp_prim_render_options.method). The seeds' methods come first,
 * faithful to their fixed-pipeline algorithms; the last two use programmable
 * hardware. docs/render-methods.md compares them.
 */
typedef enum asp_prim_render_method {
    /* Sum (colour x alpha, alpha) of the fragments near the front-most
     * alpha-tested layer (within depth_window of it along the eye ray; the
     * visibility splatting of Pajarola et al. 5.3) in a float target, then
     * divide per pixel (their 5.4): the partition of unity is restored after
     * projection, so no over-bright or too-dark spots (thesis 5.3.1). Back
     * faces are culled (the normalisation makes up for their weight). Default. */
    ASP_PRIM_RENDER_NORMALIZED = 0,
    /* Order-independent form of the thesis's "conceptually correct" algorithm
     * (4.4, Fig. 4.4-4.5): pass 1 keeps the front-most alpha-tested
     * primitive's id and depth per pixel; pass 2 adds only fragments of that
     * primitive or its neighbours within depth_window behind it; then
     * normalise, back faces culled. No sorting, so no sorting artefacts
     * (thesis 5.3.3). */
    ASP_PRIM_RENDER_PREFIX = 1,
    /* Journal Fig. 10 / thesis 4.4.4: front to back by eye-to-centre
     * distance; each front-facing primitive and its not yet drawn neighbours
     * are added (colour x alpha), then the primitive is written to depth only
     * where alpha > alpha_ref (0.1, thesis Fig. 4.13), locking its pixels.
     * Back faces are culled. */
    ASP_PRIM_RENDER_OVERLAP = 2,
    /* Thesis 4.4.2: depth pass pushed back by depth_window along the eye
     * rays, then every front face within it is added. */
    ASP_PRIM_RENDER_TWO_PASS = 3,
    /* Thesis 4.4.3, hard: back to front, front faces added, back faces reset
     * the pixels where their alpha > 0 to black. */
    ASP_PRIM_RENDER_DARK_BACKFACE = 4,
    /* Thesis 4.4.3, soft: back faces subtract their alpha from every channel
     * (clamped at 0) instead, darkening by alpha. */
    ASP_PRIM_RENDER_DARK_BACKFACE_SOFT = 5,
    /* Thesis appendix C "Blend All" (Fig. 4.3): everything added, no
     * visibility at all. A reference for what visibility fixes. */
    ASP_PRIM_RENDER_BLEND_ALL = 6,
    /* Thesis appendix C "No Blend": opaque, depth-tested texels where
     * alpha > alpha_ref, for strict (non-overlapping) domains. */
    ASP_PRIM_RENDER_NO_BLEND = 7,
    /* Journal Fig. 12b: the support polygons drawn opaque and unblended
     * (texture colour), each trimmed to its domain's footprint (texels of
     * alpha > 0: the convex hull of the domain's points, journal 3.1), a
     * flat polygon soup. --outline shows the whole rectangles. */
    ASP_PRIM_RENDER_POLYGONS = 8
} asp_prim_render_method;

/** Flags for asp_prim_render_options.flags; 0 is the default. */
enum asp_prim_render_flags {
    ASP_PRIM_RENDER_OUTLINE = 1 << 0,       /* draw each support rectangle's edges (journal Fig. 12b) */
    ASP_PRIM_RENDER_COLOR_BY_DOMAIN = 1 << 1, /* one colour per primitive, neighbours distinct (journal Fig. 5d) */
    ASP_PRIM_RENDER_NO_NORMAL_MAP = 1 << 2, /* light with the primitive normal even when the level has a normal map */
    /* overlap method as the pseudocode of journal Fig. 10 / thesis 4.4.4 reads: the neighbours a
     * front-facing primitive adds are drawn even when they face away (default: back faces culled,
     * thesis 5.3.1) */
    ASP_PRIM_RENDER_OVERLAP_BACKFACES = 1 << 3,
    /* Debug drawings of the thesis viewer (appendix C), drawn over the image without depth test: each
     * primitive's PCA axes from its centre, axis_u red (half_u long), axis_v green (half_v), the normal
     * blue (the shorter half extent) */
    ASP_PRIM_RENDER_DEBUG_EIGENVECTORS = 1 << 4,
    /* ... and the midpoints of the texels with alpha > 0 as one-pixel magenta dots */
    ASP_PRIM_RENDER_DEBUG_TEXELS = 1 << 5,
    /* ... and the affine triangulation given by asp_prim_renderer_set_debug_lines as cyan lines */
    ASP_PRIM_RENDER_DEBUG_TRIANGULATION = 1 << 6
};

/** The sRGB colours of the debug drawings (ASP_PRIM_RENDER_DEBUG_*). */
#define ASP_PRIM_DEBUG_AXIS_U_RGB 255, 0, 0
#define ASP_PRIM_DEBUG_AXIS_V_RGB 0, 255, 0
#define ASP_PRIM_DEBUG_NORMAL_RGB 0, 0, 255
#define ASP_PRIM_DEBUG_TEXEL_RGB 255, 0, 255
#define ASP_PRIM_DEBUG_TRIANGLE_RGB 0, 255, 255

/**
 * Rendering options of a domain-primitive renderer; the zero value means
 * defaults. Shading is that of asp_render_to_image (colour * (0.25 + 0.75
 * |n . l|), ASP_RENDER_UNLIT turns it off) with n the primitive's normal, or
 * per texel from the level's normal map when it has one (journal section 6:
 * relighting), so the light direction of asp_render_desc applies.
 */
typedef struct asp_prim_render_options {
    asp_prim_render_method method;
    float alpha_ref;     /* alpha test of every depth write (locks, front layer); 0 = 0.1 (thesis
                            Fig. 4.13); < 0 = 0 (every texel with alpha > 0); at most 1 */
    float transparency;  /* global opacity factor scaling alpha (journal section 6); 0 = 1 (opaque); else in (0, 1] */
    float depth_window;  /* world units along the eye ray: two-pass offset and the normalized / prefix
                            window; 0 = the renderer's default (asp_prim_renderer_options reports it);
                            < 0 = none */
    unsigned flags;      /* asp_prim_render_flags */
    uint8_t outline_color[4]; /* sRGB; all 0 = green 0,255,0 (journal Fig. 12b) */
    float crease_angle;  /* degrees: two quasi-flat primitives (curvature < 0.01) whose domains meet
                            where their support planes cross, with normals more than this apart, meet
                            at a sharp crease, and each is clipped by the other's plane (beyond the
                            seeds, docs/render-methods.md); 0 = ASP_PRIM_CREASE_ANGLE_DEFAULT;
                            < 0 or >= 180 = never clip, exactly the seeds' methods */
} asp_prim_render_options;

/**
 * Gives a domain-primitive renderer the line segments its
 * ASP_PRIM_RENDER_DEBUG_TRIANGULATION drawing shows (6 floats per segment in
 * the renderer's frame, as asp_prim_level_triangles writes them with the
 * renderer's origin; copied, replacing earlier ones; segments 0 clears).
 * Makes r's context current. Returns 0, ASP_EUNSUPPORTED (not a
 * domain-primitive renderer), ASP_EINVAL (NULL lines with segments > 0),
 * ASP_ENOMEM, ASP_EGL.
 */
int asp_prim_renderer_set_debug_lines(asp_renderer *r, const float *lines, size_t segments, asp_error *err);

/**
 * Makes asp_prim_build with desc do its texture fills on the GPU of gl
 * (thesis 3.6): sets desc->fill and desc->fill_user (the typed gl stands
 * behind prim's untyped callback pointer, so no caller passes a void *). gl
 * must outlive the build and is made current by it; use it from its thread
 * only. Each fill: a GL 4.5 compute shader computes per texel what the
 * CPU's fill computes (the radial sums of 3.3.2; the affine interpolation of
 * 3.3.3 in the kept triangles and the radial fringe outside), over the
 * samples and triangles binned to the texel's 8 x 8 cell, in the CPU's order
 * and in double precision; the library reads f back and finishes on the CPU
 * as the thesis proposes. A fill fails asp_prim_build with ASP_EGL (the
 * shader or a GL call failed), ASP_EUNSUPPORTED (a batch of 2^31 texels or
 * more) or ASP_ENOMEM.
 */
void asp_prim_gpu_fill_set(asp_prim_desc *desc, asp_gl_context *gl);

/** Default crease angle (degrees) of asp_prim_render_options.crease_angle. */
#define ASP_PRIM_CREASE_ANGLE_DEFAULT 60.0f

/** Options of asp_prim_renderer_create; the zero value means defaults. */
typedef struct asp_prim_renderer_desc {
    asp_prim_render_options options;
    double origin[3]; /* world point the renderer's frame is centred on: primitive centres are drawn at
                         centre - origin (pass a cloud's origin to share its camera); zero = world origin */
} asp_prim_renderer_desc;

/**
 * Uploads level (one level of an asp_dps: primitives, neighbour lists, RGBA
 * atlas and the normal atlas when present) to GL: one storage buffer of
 * primitives, one of neighbour indices and the atlas as one sRGB texture with
 * linear filtering (straight colour, alpha = basis function). Returns a
 * renderer drawing every primitive as its textured support rectangle with
 * desc->options (changeable later with asp_prim_renderer_set_options).
 * level is only read during the call. Makes gl current.
 * Returns 0; ASP_EDEGENERATE (no primitives); ASP_EFORMAT (a non-finite
 * value, a texture rectangle outside the atlas, a neighbour index out of
 * range, a missing atlas; names the primitive); ASP_EINVAL (bad options, as
 * asp_prim_renderer_set_options); ASP_EUNSUPPORTED (an atlas larger than
 * GL_MAX_TEXTURE_SIZE, more than 2^31 - 1 primitives); ASP_EGL; ASP_ENOMEM.
 * *out is unchanged on failure; free it with asp_renderer_destroy.
 */
int asp_prim_renderer_create(asp_gl_context *gl, const asp_dps_level *level, const asp_prim_renderer_desc *desc,
                             asp_renderer **out, asp_error *err);

/**
 * Sets the options of a domain-primitive renderer for the following frames
 * (no GL calls, no re-upload: cheap enough per key press). Returns 0;
 * ASP_EINVAL for an unknown method or flag, a NaN option, alpha_ref > 1 or
 * transparency outside [0, 1] (the renderer keeps its options); ASP_EUNSUPPORTED
 * if r is not a domain-primitive renderer (names its kind).
 */
int asp_prim_renderer_set_options(asp_renderer *r, const asp_prim_render_options *options, asp_error *err);

/**
 * Fills *out with r's options as resolved (defaults filled in: alpha_ref,
 * transparency, depth_window in world units, outline colour, crease_angle in
 * degrees or -1 when clipping is off). Returns 0 or
 * ASP_EUNSUPPORTED if r is not a domain-primitive renderer.
 */
int asp_prim_renderer_options(const asp_renderer *r, asp_prim_render_options *out, asp_error *err);

/**
 * Method names: "normalized", "prefix", "overlap", "two-pass",
 * "dark-backface", "dark-backface-soft", "blend-all", "no-blend", "polygons"
 * (the enum order). asp_prim_render_method_name returns NULL past the last,
 * so callers can list them. Parse returns 0 or ASP_EINVAL naming the choices.
 */
const char *asp_prim_render_method_name(asp_prim_render_method m);
int asp_prim_render_method_parse(const char *name, asp_prim_render_method *out, asp_error *err);

/* ------------------------------------------------------------------------ */
/* Hybrid: primitives where they hold, points where they fail (issue 18)    */
/* ------------------------------------------------------------------------ */

/* Which primitives hold is GL-free: asp_hybrid_split in prim.h, whose thresholds (and ASP_HYBRID_*
 * defaults) the last three fields of asp_hybrid_desc pass on. */

/** Options of the hybrid renderer; the zero value means defaults. */
typedef struct asp_hybrid_desc {
    asp_prim_render_options prim;   /* alpha_ref, depth_window, crease_angle, flags (outline and colour by domain
                                       excepted); method and transparency are not used: the hybrid has its own
                                       normalised passes */
    asp_splat_renderer_desc splat;  /* kernel, epsilon, tolerance (the point part's tau, asp_renderer_set_lod),
                                       hierarchy options, default colour; mode, lighting PIXEL and clip_planes
                                       are not used */
    double origin[3];               /* as asp_prim_renderer_desc.origin; the points must be in this frame too
                                       (cloud->origin equal to it) */
    float error_limit;              /* 0 = ASP_HYBRID_ERROR_LIMIT; else > 0 */
    float turned_limit;             /* 0 = ASP_HYBRID_TURNED_LIMIT; else > 0 */
    float coverage_min;             /* 0 = ASP_HYBRID_COVERAGE_MIN; else > 0 */
} asp_hybrid_desc;

/**
 * A renderer drawing level's kept primitives (asp_hybrid_split) and, in
 * place of the others, their domains' points (and any point the kept
 * primitives leave uncovered) as the blended splats of seed 001, from a point
 * hierarchy of those points cut per frame by the splat tolerance. Both add
 * (colour x weight, weight) into one float target after one shared
 * visibility pass (the primitives' alpha-tested depth pushed back by the depth
 * window, the splats' pushed back by epsilon), and one resolve divides by
 * the weight (Pajarola et al. 2003 5.4), so there is no seam where they meet.
 * Back-facing primitives are culled as in the normalized method. points:
 * the level's source points, in the frame of desc->origin; without radii
 * each point gets the distance to its 8th neighbour. asp_renderer_set_lod
 * sets the point part's tolerance; asp_renderer_stats_get reports primitives
 * + splats drawn (count) and the points part (points, nodes, tolerance).
 * Makes gl current. Returns 0; the errors of asp_hybrid_split,
 * asp_prim_renderer_create and asp_splat_renderer_create; ASP_ENOMEM.
 * *out is unchanged on failure; free it with asp_renderer_destroy.
 */
int asp_hybrid_renderer_create(asp_gl_context *gl, const asp_dps_level *level, const asp_cloud *points,
                               const asp_hybrid_desc *desc, const asp_context *ctx, asp_renderer **out,
                               asp_error *err);

/** Fills *out with the split a hybrid renderer made. Returns 0 or ASP_EUNSUPPORTED for another kind. */
int asp_hybrid_renderer_counts(const asp_renderer *r, asp_hybrid_counts *out, asp_error *err);

/* ------------------------------------------------------------------------ */
/* Triangle meshes (issue 14: the textured-mesh baseline of seed 004 2.2-2.3) */
/* ------------------------------------------------------------------------ */

/**
 * A material of asp_render_mesh: where a triangle gets its colour. The rule
 * is the mesh sampler's (asp__surface_point), so samples of a mesh and the
 * mesh itself show one colour: the texture when the mesh has UVs and the
 * material a texture, else the vertex colours when the mesh has them, else
 * color.
 */
typedef struct asp_render_material {
    float color[4];           /* RGBA in 0..1, sRGB-encoded (an OBJ Kd as the sampler reads it: 255 Kd) */
    const asp_image *texture; /* diffuse texture or NULL; rows top first, UV v = 0 is its bottom row */
} asp_render_material;

/**
 * A triangle mesh as plain arrays (render knows no files: the scene loader
 * fills this from an asp_mesh, mesh.h). Everything is borrowed for the
 * create call only.
 */
typedef struct asp_render_mesh {
    size_t vertex_count, triangle_count;
    double origin[3];             /* world position = origin + positions[i] */
    const float *positions;       /* 3 * vertex_count */
    const float *normals;         /* 3 * vertex_count, or NULL: face normals */
    const float *uvs;             /* 2 * vertex_count, or NULL (GL convention: v = 0 is the image bottom) */
    const uint8_t *colors;        /* 4 * vertex_count sRGB RGBA, or NULL */
    const uint32_t *triangles;    /* 3 * triangle_count vertex indices */
    const uint32_t *material_ids; /* triangle_count indices into materials, or NULL: material 0 */
    size_t material_count;        /* 0 = one light grey material (200, 200, 200), like the point renderers */
    const asp_render_material *materials;
} asp_render_mesh;

/** Flags for asp_mesh_renderer_desc.flags; 0 is the default. */
enum asp_mesh_renderer_flags {
    /* Light each triangle by its face normal (faceted), not the interpolated vertex normals. */
    ASP_MESH_RENDER_FLAT = 1 << 0
};

/** Options of the mesh renderer; the zero value means defaults. */
typedef struct asp_mesh_renderer_desc {
    unsigned flags;    /* asp_mesh_renderer_flags */
    double origin[3];  /* world point the renderer's frame is centred on (as asp_prim_renderer_desc.origin):
                          vertices are drawn at mesh->origin + position - origin; zero = world origin */
} asp_mesh_renderer_desc;

/**
 * Uploads mesh to GL (one vertex buffer per array, one index buffer with the
 * triangles grouped by material, each texture as a GL_SRGB8_ALPHA8 texture
 * with a full mipmap chain, trilinear filtering and GL_REPEAT wrapping) and
 * returns a renderer drawing the opaque, depth-tested, two-sided triangles.
 * Colours follow asp_render_material's rule; shading is that of
 * asp_render_to_image (colour * (0.25 + 0.75 |n . l|) in linear light,
 * ASP_RENDER_UNLIT, the light of asp_render_desc) with n the interpolated
 * vertex normal, or the face normal with ASP_MESH_RENDER_FLAT or without
 * normals, so a mesh and discs sampled from it light alike. Texture alpha is
 * ignored (opaque, like the discs). asp_renderer_count gives the triangles.
 * mesh is only read during the call. Makes gl current.
 * Returns 0; ASP_EDEGENERATE (no triangles); ASP_EFORMAT (a vertex index or
 * material id out of range, a non-finite position, naming it); ASP_EUNSUPPORTED
 * (more than 2^31 - 1 indices, a texture larger than GL_MAX_TEXTURE_SIZE);
 * ASP_EGL; ASP_ENOMEM. *out is unchanged on failure; free it with
 * asp_renderer_destroy.
 */
int asp_mesh_renderer_create(asp_gl_context *gl, const asp_render_mesh *mesh, const asp_mesh_renderer_desc *desc,
                             asp_renderer **out, asp_error *err);

/* ------------------------------------------------------------------------ */
/* The renderer table (STYLE.md 9b: one table, owned by render)             */
/* ------------------------------------------------------------------------ */

/* ------------------------------------------------------------------------ */
/* The cut across the levels of a .dps (issue 18, docs/cut.md)              */
/* ------------------------------------------------------------------------ */

/** Options of asp_cut_renderer_create; the zero value means defaults. */
typedef struct asp_cut_renderer_desc {
    float tolerance;      /* screen tolerance in pixels of asp_dps_cut_view (0 = 1; < 0 = 0: the finest level
                             everywhere); asp_renderer_set_lod changes it later */
    float alpha_ref;      /* alpha test of the front layer, as asp_prim_render_options (0 = 0.1) */
    float transparency;   /* global opacity (0 = 1) */
    double fade_seconds;  /* how long a change of the cut blends in (0 = 0.25; < 0 = no fade) */
    float size_weight;    /* asp_dps_cut_view.size_weight: 0 = 0.2 (bench_field: at equal SSIM about 3x less
                             frame time than the geometric error alone), < 0 = the geometric error alone */
    double origin[3];     /* as asp_prim_renderer_desc.origin */
} asp_cut_renderer_desc;

/**
 * Uploads every level of dps (which must have links, asp_dps_has_links, unless it has one level) once: one
 * storage buffer of primitives and one sRGB atlas texture per level. Each frame it takes the cut of
 * asp_dps_cut_update for the view (per instance, see asp_cut_renderer_set_instances) and draws it with the
 * normalized method (asp_prim_render_method ASP_PRIM_RENDER_NORMALIZED: the front layer, the sum of
 * colour x alpha x d_f and alpha x d_f within a depth window of it, then the division), so the levels
 * blend as one surface. The depth window of each level is half its mean primitive radius (as the prim
 * renderer's default). Normal maps, crease clipping and domain colours are not drawn. dps is borrowed and
 * must outlive the renderer. asp_renderer_count is the number of primitives drawn in the last frame;
 * asp_renderer_stats_get gives it with the tolerance. Errors: ASP_EINVAL (no links: "no links between
 * levels ..."; bad option), ASP_EUNSUPPORTED (an atlas larger than GL allows), ASP_EGL, ASP_ENOMEM.
 */
int asp_cut_renderer_create(asp_gl_context *gl, const asp_dps *dps, const asp_cut_renderer_desc *desc,
                            asp_renderer **out, asp_error *err);

/**
 * Draws count instances from now on (0 = back to one instance at the identity), instance i placed by the
 * column-major matrix models[16 i .. 16 i + 15] (rotation, translation and a uniform scale; renderer
 * frame to world); each instance gets its own cut for its own distance, and all share one normalized
 * accumulation. Instances whose bounding sphere (the dps frame) lies outside the view are skipped. The
 * matrices are copied. Returns 0, ASP_EINVAL (not a cut renderer), ASP_ENOMEM.
 */
int asp_cut_renderer_set_instances(asp_renderer *r, const float *models, size_t count, asp_error *err);

/**
 * The caller's clock in seconds for the next frame: the fade advances by the difference to the previous
 * frame's time. Without it (or before the second timed frame) every frame shows its target cut at once.
 * Returns 0 or ASP_EINVAL (not a cut renderer, or time not finite).
 */
int asp_cut_renderer_set_time(asp_renderer *r, double seconds, asp_error *err);

/** What a renderer of the table can draw (asp_renderer_kind.inputs). */
enum asp_render_input_bits {
    ASP_RENDER_INPUT_POINTS = 1 << 0, /* asp_render_source.cloud or .hier: points, splats */
    ASP_RENDER_INPUT_PRIMS = 1 << 1,  /* asp_render_source.level: domain primitives */
    ASP_RENDER_INPUT_MESH = 1 << 2    /* asp_render_source.mesh: a triangle mesh */
};

/**
 * What to draw, as a scene loader hands it over (asp_scene_render_source in
 * scene.h). Everything is borrowed for the create call, except hier, which a
 * hierarchy renderer keeps a reference to (it must outlive the renderer).
 */
typedef struct asp_render_source {
    const asp_cloud *cloud;      /* points in the cloud's local frame; NULL when only hier or level is given */
    const asp_hier *hier;        /* optional: a hierarchy of cloud (or alone, e.g. a .hier file): splat and
                                    square draw it instead of building one; NULL = built from cloud */
    const float *clip_planes;    /* 8 floats per point of cloud (asp_crease_clip_planes), NULL = none */
    const asp_dps_level *level;  /* domain primitives (the prim renderer) */
    const asp_dps *dps;          /* every level of a .dps with its links (the cut renderer; issue 18) */
    const asp_render_mesh *mesh; /* a triangle mesh (the mesh renderer), drawn in the frame of origin */
    double origin[3];            /* the frame primitives and meshes are drawn in (asp_prim_renderer_desc.origin);
                                    for points it is cloud->origin (or asp_hier_origin), which the point
                                    renderers use by themselves */
} asp_render_source;

/** Options of every renderer of the table; the zero value means defaults. */
typedef struct asp_renderer_options {
    asp_disc_renderer_desc disc;     /* clip_planes comes from the source */
    asp_splat_renderer_desc splat;   /* clip_planes comes from the source */
    asp_square_renderer_desc square;
    asp_prim_render_options prim;
    asp_mesh_renderer_desc mesh;     /* origin comes from the source */
    asp_hybrid_desc hybrid;          /* origin comes from the source; prim: these options' prim when zero */
    asp_cut_renderer_desc cut;       /* origin comes from the source */
} asp_renderer_options;

/**
 * One row of the renderer table (src/render/renderer_table.c). Adding a
 * renderer kind is one new file, src/render/<kind>_renderer.c, that fills the
 * renderer interface's function table (src/render/internal.h says which
 * entries are required and what a NULL optional entry means), plus one row
 * here with its make adapter; no other file learns of the kind, since every
 * public call on an asp_renderer dispatches through that table.
 */
typedef struct asp_renderer_kind {
    const char *name;   /* "disc", "splat", "square", "prim", "mesh", "hybrid" */
    const char *noun;   /* what asp_renderer_count counts: "points", "splats", "primitives", "triangles" */
    unsigned inputs;    /* asp_render_input_bits it draws */
    int has_lod;        /* draws a cut of the point hierarchy: tau and budgets apply (asp_renderer_set_lod) */
    /*
     * Makes the renderer from src with the options of its kind; ctx (threads
     * and allocator of a hierarchy build; NULL = defaults) is passed on.
     * Errors of the renderer's own create function, or ASP_EUNSUPPORTED when
     * src lacks what the kind draws ("renderer 'prim' draws domain
     * primitives (a .dps input)").
     */
    int (*create)(asp_gl_context *gl, const asp_render_source *src, const asp_renderer_options *options,
                  const asp_context *ctx, asp_renderer **out, asp_error *err);
} asp_renderer_kind;

/**
 * Row i of the renderer table, in the order "disc", "splat", "square",
 * "prim", "mesh", "hybrid", "cut" (the viewer's 1..9 keys follow it), or NULL past the end.
 * Thread safe.
 */
const asp_renderer_kind *asp_renderer_kind_at(size_t i);

/** Number of rows of the renderer table. */
size_t asp_renderer_kind_count(void);

/**
 * The row named name that draws at least one of inputs (asp_render_input_bits;
 * 0 = any). Returns 0 and *out, or ASP_EINVAL "unknown renderer 'x' (expected
 * disc, splat, square)" listing the names that draw inputs. Thread safe.
 */
int asp_renderer_kind_find(const char *name, unsigned inputs, const asp_renderer_kind **out, asp_error *err);

#ifdef __cplusplus
}
#endif
#endif
