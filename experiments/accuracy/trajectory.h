/* Particle trajectories: each frame's particle positions and velocities in
 * one binary file (`run --trajectory` writes OUT/trajectory.bin), and the
 * trajectory error of a run against a reference run's file (`run
 * --trajectory-ref RUN_DIR`, SPEC 11): at every frame end
 *
 *   pos_rms = sqrt(mean_p |x_p - x*_p|^2) / dx,  pos_max = max_p |x_p - x*_p| / dx,
 *   vel_rms = sqrt(sum_p |v_p - v*_p|^2 / sum_p |v*_p|^2)
 *
 * (x*, v*: the reference's particle p at the same frame; particles are
 * matched by their identity, Particles.id, not by their storage order, which
 * the locality sort changes). With --dt-from RUN_DIR (reference_run.h) both
 * runs take the same time steps, so the difference is solver error; a run
 * against itself gives exactly zero.
 *
 * ------------------------------------------------------------------------
 * File format (version 1). Every number little-endian as written by an
 * x86-64 host: u32/u64 unsigned integers, f64 IEEE doubles.
 * ------------------------------------------------------------------------
 *   header, 96 bytes:
 *     char[8]  magic "MPMTRAJ1"
 *     u32      version (1)
 *     u32      header bytes (96)
 *     char[64] scene name, NUL-padded
 *     f64      dx [m]
 *     u64      particles at the start (the scene's initial count)
 *   then one record per frame, in frame order:
 *     u32      frame (the frames.csv "frame": the state at that frame's end)
 *     u32      0 (padding)
 *     f64      t [s] at the frame's end
 *     u64      n, the particles at that time (sources add some)
 *     f64[3n]  positions x, y, z of the particles with id 0, 1, ..., n-1
 *     f64[3n]  velocities, in the same order
 * A frame's record is 24 + 48 n bytes. */
#ifndef MPM_TRAJECTORY_H
#define MPM_TRAJECTORY_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "core/particles.h"

#define TRAJECTORY_FILE "trajectory.bin"
#define TRAJECTORY_MAGIC "MPMTRAJ1"
#define TRAJECTORY_HEADER_BYTES 96

typedef struct {
    FILE *f;
    char path[1100];
    double *buf;         /* 6 per particle: the frame in id order */
    size_t cap;
} TrajectoryWriter;

/* Creates DIR/trajectory.bin and writes the header. */
int trajectory_writer_open(TrajectoryWriter *w, const char *dir, const char *scene, double dx, size_t particles);
/* Appends the frame's record (the particles in id order). */
int trajectory_write_frame(TrajectoryWriter *w, int frame, double t, const Particles *p);
void trajectory_writer_close(TrajectoryWriter *w);

typedef struct {
    FILE *f;
    char path[1100];
    char scene[64];
    double dx;
    uint64_t particles;
    int frames;          /* records in the file */
    double *ref;         /* the reference frame, 6 per particle */
    size_t cap;
} TrajectoryReader;

typedef struct {
    double pos_rms, pos_max, vel_rms; /* NAN when undefined (vel_rms of a reference at rest) */
} TrajectoryError;

/* Opens RUN_DIR/trajectory.bin of a reference run and checks it against
 * this run: the same scene and initial particle count (MPM_EINPUT naming
 * both otherwise), at least `frames` records. */
int trajectory_reader_open(TrajectoryReader *r, const char *run_dir, const char *scene, size_t particles,
                           int frames);
/* Reads the next record, which must be `frame` with p->n particles, and
 * compares p with it (dx: this run's grid spacing). */
int trajectory_compare_frame(TrajectoryReader *r, int frame, const Particles *p, double dx, TrajectoryError *e);
void trajectory_reader_close(TrajectoryReader *r);

#endif
