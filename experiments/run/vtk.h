/* Particles (and optionally the grid) as a ParaView time series: one VTK XML
 * PolyData file (.vtp, binary data appended raw) per frame and a .pvd
 * collection that lists them with their simulated time (issue 19).
 *
 *   DIR/particles.pvd, DIR/particles_NNNN.vtp   frame 0 is the initial state,
 *       frame k the state at the end of frame k; point data (Float32 unless
 *       said): velocity [m/s] (3), material (Int32, index into the scene's
 *       materials), id (Int64, particles.h), J = det F, plastic_J (Jp, 1
 *       for materials without plasticity), von_mises [Pa]: the von Mises
 *       stress sqrt(3/2 s:s) of the Cauchy stress sigma = P F^T / J (s its
 *       deviator, P the fixed-corotated first Piola-Kirchhoff stress of
 *       fcr.h with the particle's material), mass [kg], volume [m^3] (rest).
 *   DIR/grid.pvd, DIR/grid_NNNN.vtp (with grid = 1)   the active grid nodes
 *       of the frame's last step at their positions (coord * dx): mass [kg]
 *       and velocity [m/s], the velocity after that step's solve (v^n+1),
 *       and momentum [kg m/s] (mass times velocity, which light nodes do not
 *       dominate); nodes lighter than min_mass times the heaviest are left
 *       out.
 *
 * Every point is also a vertex cell, so ParaView draws the points as they
 * are. The .pvd is rewritten after every frame: a run that stops leaves a
 * valid series of the frames it wrote. */
#ifndef MPM_VTK_H
#define MPM_VTK_H

#include "core/grid.h"
#include "core/material.h"
#include "core/particles.h"

/* The default of min_mass (vtk_series_open). A node that only the tail of
 * the particles' weights reaches has little mass, while the weights'
 * gradients, through which the elastic forces reach it, fall off more
 * slowly (a quadratic B-spline's w'/w grows without bound at its support's
 * edge): the solved velocity of such a node can be thousands of times any
 * particle's, and it is all a ParaView colour map would show (stretched-box
 * at scale 5: nodes under 1e-3 of the heaviest node's mass up to 282 m/s,
 * the particles at most 0.09 m/s). The particles see those velocities only
 * through the same small weights. */
#define VTK_GRID_MIN_MASS_DEFAULT 1e-3

typedef struct {
    char dir[1024];
    int grid;               /* also the grid series */
    double min_mass;        /* nodes lighter than min_mass x the frame's heaviest are left out */
    double *t;              /* simulated time of each written particle frame */
    int *frame;
    int n, cap;
    double *grid_t;
    int *grid_frame;
    int n_grid, cap_grid;
} VtkSeries;

/* Makes DIR (and its parents). min_mass: the grid files leave out the nodes
 * lighter than min_mass times the frame's heaviest node (0: none). */
int vtk_series_open(VtkSeries *s, const char *dir, int grid, double min_mass);
/* Writes frame `frame` at time t; g / grid_v (3 per node) may be NULL (no grid file then). */
int vtk_series_frame(VtkSeries *s, int frame, double t, const Particles *p, const Material *materials, int n_materials,
                     const Grid *g, const double *grid_v);
void vtk_series_free(VtkSeries *s);

/* The von Mises stress of the Cauchy stress of fixed-corotated elasticity at F. */
double vtk_von_mises(const double F[9], double mu, double lambda);

#endif
