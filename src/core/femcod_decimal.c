/* Correctly rounded decimal conversions of C's library for femcod_strings (format_real,
 * parse_real), which uses them where its own exact extended-precision path does not apply
 * (near a rounding tie, more than 18 digits, a decimal exponent beyond 27): snprintf is
 * variadic, which Fortran cannot call portably, hence this wrapper. glibc's printf and
 * strtod convert exactly (correct rounding, round half to even). */
#include <stdio.h>
#include <stdlib.h>

/* x with `digits` significant digits in exponent form ("-1.2345e-07"); returns the
 * length written (at most size - 1). */
int femcod_decimal_e(double x, int digits, char *buffer, int size)
{
    return snprintf(buffer, (size_t) size, "%.*e", digits - 1, x);
}

/* The double nearest to the decimal in `text` (NUL-terminated). */
double femcod_decimal_read(const char *text)
{
    return strtod(text, NULL);
}
