/* femcod from C: Hertz's sphere on a half-space (doc/python.md, "The C library").
 *
 * A paraboloid of radius R = 200 nm on an elastic body (E = 200 GPa, nu = 0.25) is
 * pressed against a rigid flat by P = 1000 nN; femcod's cg solver gives the contact
 * area, the approach and the largest pressure, printed beside Hertz's closed forms
 * (Johnson, Contact Mechanics, eqs. 4.22-4.23):
 *   a = (3 P R / 4 E*)^(1/3),  delta = a^2 / R,  p0 = 3 P / (2 pi a^2),  E* = E / (1 - nu^2).
 *
 *   cc doc/femcod_example.c -I$PREFIX/include -L$PREFIX/lib -lfemcod -Wl,-rpath,$PREFIX/lib -lm
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "femcod.h"

/* Called by the solver with its progress; returning non-zero would stop it. */
static int progress(int step, int contacts, double load_nN, double seconds, void *user) {
  int *calls = (int *)user;
  (*calls)++;
  if (step > 0) printf("progress: state %d, %d contacts at %g nN after %.3f s\n", step, contacts, load_nN, seconds);
  return 0;
}

static int fail(femcod_session *s, const char *what, int code) {
  char text[4096];
  femcod_message(s, text, sizeof text);
  fprintf(stderr, "%s failed (status %d): %s\n", what, code, text);
  femcod_destroy(s);
  return 1;
}

int main(void) {
  const int np = 64;
  const double pixel = 1.0, radius = 200.0, young = 200.0, poisson = 0.25, load = 1000.0;
  const double pi = acos(-1.0);
  double *heights = malloc(sizeof(double) * np * np), *pressure = malloc(sizeof(double) * np * np);
  double area, approach, pmax;
  int calls = 0, code;
  char version[64];

  /* Heights in C order: heights[i*np + j] is row i, column j. */
  for (int i = 0; i < np; i++)
    for (int j = 0; j < np; j++) {
      double x = (j - (np - 1) / 2.0) * pixel, y = (i - (np - 1) / 2.0) * pixel;
      heights[i * np + j] = -(x * x + y * y) / (2 * radius);
    }

  femcod_session *s = femcod_create();
  if (!s) return 1;
  femcod_version(version, sizeof version);
  printf("femcod %s\n", version);
  if ((code = femcod_set_heights(s, np, pixel, heights, NULL, young, poisson, 0))) return fail(s, "set_heights", code);
  femcod_set_option(s, "--solver", "cg");
  femcod_set_option(s, "--loads", "1000");
  if ((code = femcod_solve(s, progress, &calls))) return fail(s, "solve", code);
  femcod_state_value(s, 1, "area_nm2", &area);
  femcod_state_value(s, 1, "approach_nm", &approach);
  if ((code = femcod_state_map(s, 1, "pressure", pressure, (int64_t)np * np))) return fail(s, "state_map", code);
  pmax = 0;
  for (int k = 0; k < np * np; k++)
    if (pressure[k] > pmax) pmax = pressure[k];

  double estar = young / (1 - poisson * poisson);
  double a = cbrt(3 * load * radius / (4 * estar));
  printf("quantity,femcod,hertz\n");
  printf("area_nm2,%.6g,%.6g\n", area, pi * a * a);
  printf("approach_nm,%.6g,%.6g\n", approach, a * a / radius);
  printf("max_pressure_GPa,%.6g,%.6g\n", pmax, 3 * load / (2 * pi * a * a));
  printf("progress_calls,%d\n", calls);

  /* A refused combination comes back as a status and a message, never an exit. */
  femcod_set_option(s, "--adhesion", "dugdale");
  code = femcod_solve(s, NULL, NULL);
  char text[4096];
  femcod_message(s, text, sizeof text);
  printf("refused,%d,%s\n", code, text);

  femcod_destroy(s);
  free(heights);
  free(pressure);
  return code == 2 ? 0 : 1;
}
