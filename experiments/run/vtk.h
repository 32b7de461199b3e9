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
 * valid series of the frames it wrote.
 *
 * Over MPI ranks (docs/distributed.md) each rank writes its own particles
 * and owned grid nodes as a piece, NAME_NNNN_rK.vtp, and rank 0 writes
 * NAME_NNNN.pvtp, which lists the pieces, and the .pvd, which lists the
 * .pvtp files: ParaView opens the .pvd as on one process. */
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
    int rank, ranks;        /* over ranks: this rank's piece; rank 0 writes the lists */
    int grid;               /* also the grid series */
    double min_mass;        /* nodes lighter than min_mass x the frame's heaviest are left out */
    double *t;              /* simulated time of each written particle frame */
    int *frame;
    int n, cap;
    double *grid_t;
    int *grid_frame;
    int n_grid, cap_grid;
} VtkSeries;

/* A frame's grid: its nodes and velocities (3 per node), the nodes this
 * rank owns (NULL: all) and the whole scene's heaviest node
 * (vtk_heaviest_node, maximised over the ranks by the caller). */
typedef struct {
    const Grid *g;
    const double *v;
    const unsigned char *owned;
    double heaviest;
} VtkGridFrame;

/* Makes DIR (and its parents; on every rank). min_mass: the grid files
 * leave out the nodes lighter than min_mass times the frame's heaviest node
 * (0: none). rank of ranks: this process's piece (1 rank: no pieces).
 * Writes nothing the other ranks wait for: a caller over ranks agrees on
 * the status. */
int vtk_series_open(VtkSeries *s, const char *dir, int grid, double min_mass, int rank, int ranks);
/* Writes frame `frame` at time t; grid NULL: no grid file. */
int vtk_series_frame(VtkSeries *s, int frame, double t, const Particles *p, const Material *materials, int n_materials,
                     const VtkGridFrame *grid);
/* The heaviest of the nodes (of the owned ones when owned is not NULL). */
double vtk_heaviest_node(const Grid *g, const unsigned char *owned);
void vtk_series_free(VtkSeries *s);

/* The von Mises stress of the Cauchy stress of fixed-corotated elasticity at F. */
double vtk_von_mises(const double F[9], double mu, double lambda);

#endif
