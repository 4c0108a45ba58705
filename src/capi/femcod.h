/* femcod.h: femcod as a C library (libfemcod.so; src/capi/femcod_capi.f90, doc/python.md).
 *
 * A session holds a problem, options and the result of its last solve:
 *
 *   femcod_session *s = femcod_create();
 *   femcod_set_heights(s, np, pixel_nm, lower, NULL, young_GPa, poisson, 0);
 *   femcod_set_option(s, "--solver", "cg");
 *   femcod_set_option(s, "--loads", "100,1000");
 *   if (femcod_solve(s, NULL, NULL) != 0) { femcod_message(s, text, sizeof text); ... }
 *   femcod_state_value(s, 1, "area_nm2", &area);
 *   femcod_state_map(s, 1, "pressure", map, (int64_t)np * np);
 *   femcod_destroy(s);
 *
 * Every function returns a status with the femcod command's exit codes' meanings:
 * 0 ok, 2 usage, 3 bad input, 4 numerical failure or memory, 5 I/O, 6 stopped by the
 * progress function; femcod_message gives the reason. Nothing prints, nothing exits.
 *
 * Arrays are C order, as in femcod's HDF5 files: a[i*np + j] is row i, column j.
 * Units: heights and pixel nm, moduli GPa, loads nN, pressures GPa.
 * Options are femcod run's (femcod run --help) that concern the solver: --solver, --loads,
 * --approach, --hardness, --boundary, --plastic, --max-contacts, --no-final-check,
 * --event-search, --tol, --max-iterations, --kernel-radius, --adhesion, --work, --range,
 * --shear-strength, --shear-slope, --tangential, --slip, --friction. Their rules are run's.
 * A session is used by one thread at a time; the solvers use OpenMP threads inside.
 */
#ifndef FEMCOD_H
#define FEMCOD_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct femcod_session femcod_session;

/* Called after each step or state and at least every 0.1 s while a solver iterates;
 * a non-zero return stops the solve (which returns 6). */
typedef int (*femcod_progress)(int step, int contacts, double load_nN, double seconds, void *user);

femcod_session *femcod_create(void);
void femcod_destroy(femcod_session *s);
int femcod_version(char *text, size_t length);
int femcod_message(femcod_session *s, char *text, size_t length);
int femcod_set_threads(int threads);

/* The problem of `femcod run --lower L [--upper U] --pixel D --young E --poisson NU`:
 * the lower surface alone is the elastic body, the other rigid and flat; with upper
 * (not NULL) both are rough. maxcont <= 0: 5 % of np^2. */
int femcod_set_heights(femcod_session *s, int np, double pixel, const double *lower, const double *upper,
                       double young, double poisson, int maxcont);
/* A problem as a deck gives it: moduli and ratios of the lower body, upper body and contact elements;
 * maxcont <= 0: 5 % of np^2. */
int femcod_set_problem(femcod_session *s, int np, double pixel, const double *lower, const double *upper,
                       const double young[3], const double poisson[3], int maxcont, const char *label);
int femcod_read_deck(femcod_session *s, const char *path);
/* `femcod run --lower PATH [--pixel D] [--remove-plane]`: a height file (ASCII matrix or Gwyddion
 * export, FILE.h5:/DATASET, NanoScope FILE[:CHANNEL]) on an elastic body against a rigid flat;
 * pixel <= 0: the file's own. Warnings (a tilt, a guessed unit): femcod_warnings, one per line. */
int femcod_read_heights(femcod_session *s, const char *path, double pixel, int remove_plane, double young,
                        double poisson);
/* What the last read of heights or the last solve warned of, one warning per line ("": none):
 * after femcod_solve, each requested state not reached (with the reason) and each tangential
 * step at a state without contact. */
int femcod_warnings(femcod_session *s, char *text, size_t length);
/* A name ending in .h5 writes the HDF5 deck; an existing file is replaced only with force != 0. */
int femcod_write_deck(femcod_session *s, const char *path, int force);
int femcod_problem_size(femcod_session *s, int *np);
int femcod_get_problem(femcod_session *s, double *pixel, int *maxcont, double young[3], double poisson[3],
                       double *lower, double *upper);
int femcod_get_label(femcod_session *s, char *text, size_t length);

/* value is "" for a flag ("--plastic"). femcod_option_names: the names it takes,
 * separated by spaces (femcod run's options that shape the answer). */
int femcod_set_option(femcod_session *s, const char *name, const char *value);
int femcod_option_names(char *text, size_t length);
int femcod_clear_options(femcod_session *s);
int femcod_solve(femcod_session *s, femcod_progress progress, void *user);

int femcod_state_count(femcod_session *s, int *count);
/* Comma-separated names: kind 0 state values, 1 maps, 2 history columns; kind 3 the
 * state values' kinds in the order of kind 0: number, count (an integer) or flag (1/0). */
int femcod_value_names(femcod_session *s, int kind, char *text, size_t length);
/* k from 1. */
int femcod_state_value(femcod_session *s, int k, const char *name, double *value);
/* Maps: pressure (GPa), gap (nm); with --plastic plastic_displacement (nm); with a tangential
 * step shear_x, shear_y (GPa), stick, slip (1 where the contact sticks, or slips). */
int femcod_state_map(femcod_session *s, int k, const char *name, double *out, int64_t size);
int femcod_history_length(femcod_session *s, int *steps);
int femcod_history(femcod_session *s, const char *name, double *out, int64_t size);

/* The last solve's result set under prefix: the files `femcod run -o PREFIX` writes (PREFIX.h5,
 * .xdmf, .summary.json, CSV tables, figures), as one set; existing results are replaced only
 * with force != 0, and only if femcod wrote them. */
int femcod_write_results(femcod_session *s, const char *prefix, int force);
/* `femcod report TARGET -o OUTPUT`: one self-contained HTML page of a result set (TARGET its
 * prefix) or of a results directory; OUTPUT "": the default name (PREFIX.report.html,
 * DIR/report.html). The page's path goes into page (capacity bytes with the NUL). */
int femcod_report(femcod_session *s, const char *target, const char *output, int force, char *page,
                  size_t capacity);

#ifdef __cplusplus
}
#endif

#endif
