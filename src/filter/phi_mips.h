/* fovea — mipmaps along φ only, for mapping a polar sample grid back to the screen (Visual-Polar
 * Sec. 3.4). On ρ the mapping to the screen is one-to-one or a magnification, so bilinear lookups
 * suffice; on φ one screen pixel near the gaze covers many samples of a column, so each level halves
 * the rows of every column and a lookup blends two levels (trilinear along φ).
 *
 * Level 0 is the grid itself. Level k has the same columns; column x holds
 * h_k(x) = max(1, ceil(h_{k-1}(x) / 2)) rows, and its row j is the average of level k-1 over the
 * angles [j, j + 1) / h_k(x), each source row weighted by how much of that span it covers. A level
 * is added while some column still has more than one row, up to max_levels.
 */
#ifndef FV_FILTER_PHI_MIPS_H
#define FV_FILTER_PHI_MIPS_H

#include "filter/grid.h"
#include "fovea/status.h"
#include "filter/kphi.h"

typedef struct fv_phi_mips fv_phi_mips;

/* Allocates the chain for grid g (copied; its col_h must outlive the chain). max_levels >= 1
 * counts level 0. No grid, an empty grid, max_levels < 1 or a column height outside [1, h]
 * -> FV_ERR_INVALID (*out NULL); no memory -> FV_ERR_NOMEM. */
fv_status fv_phi_mips_create(const fv_grid *g, int max_levels, fv_phi_mips **out, fv_error *err);
void fv_phi_mips_destroy(fv_phi_mips *m);
int fv_phi_mips_levels(const fv_phi_mips *m);
/* The grid of level k (its col_h belongs to the chain; level 0's is the caller's), NULL for k
 * outside [0, levels). */
const fv_grid *fv_phi_mips_grid(const fv_phi_mips *m, int k);

/* Builds every level from rgb (3 floats per pixel on g's storage; copied into level 0). The result
 * does not depend on threads (0 = all). */
void fv_phi_mips_build(fv_phi_mips *m, const float *rgb, int threads);

/* Colour at continuous (X, V) (filter/grid.h) and fractional level (clamped to [0, levels - 1]):
 * bilinear in the two nearest levels, blended linearly. At each level the taps and weights are
 * fv_grid_bilinear's on that level's grid. X outside [0, w] reads the edge column; V outside [0, 1)
 * wraps on a polar grid and clamps on a screen grid; a NaN X, V or level reads 0. */
void fv_phi_mips_sample(const fv_phi_mips *m, float X, float V, float level, float out[3]);

/* The chain as the kernels see it (filter/kphi.h): its sizes and the pointers to its buffers,
 * valid while the chain lives. */
void fv_phi_mips_kernel(const fv_phi_mips *m, fv_kphi_mips *out);

#endif
