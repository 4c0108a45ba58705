!> Numbers as text and text as numbers, exactly (no I/O): the shortest decimal that reads
!> back to a double (format_real, format_reals, json_number), decimals read correctly
!> rounded (parse_real, in extended precision where the compiler has it, else by C's
!> strtod through femcod_decimal.c), integers both ways without formatted I/O (safe in
!> parallel regions), and the short forms people read (sig_str, real_str, fixed_str).
!> femcod_strings re-exports every name, so its users need not know the split.
module femcod_decimal
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use, intrinsic :: ieee_exceptions, only: ieee_overflow, ieee_get_halting_mode, ieee_set_halting_mode, ieee_set_flag
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_double, c_null_char
   use femcod_kinds, only: dp, i8
   use femcod_bytes, only: eight_digits
   implicit none
   private
   public :: int_str, integer_text, real_str, fixed_str, format_real, format_reals, parse_real, parse_integer, &
      is_digit, json_number, sig_str, without_trailing_zeros

   !> A real kind of at least 64 significand bits where the compiler has one (x87's 80-bit
   !> format in gfortran on x86-64), for exact_decimal; else double, and then
   !> exact_decimal leaves every value to strtod.
   integer, parameter :: xp = merge(selected_real_kind(18), dp, selected_real_kind(18) > 0)
   !> 10**0 .. 10**27, exact in that kind (5**27 < 2**64).
   real(xp), parameter :: powers_of_ten(0:27) = [1.0e0_xp, 1.0e1_xp, 1.0e2_xp, 1.0e3_xp, 1.0e4_xp, 1.0e5_xp, &
      1.0e6_xp, 1.0e7_xp, 1.0e8_xp, 1.0e9_xp, 1.0e10_xp, 1.0e11_xp, 1.0e12_xp, 1.0e13_xp, 1.0e14_xp, &
      1.0e15_xp, 1.0e16_xp, 1.0e17_xp, 1.0e18_xp, 1.0e19_xp, 1.0e20_xp, 1.0e21_xp, 1.0e22_xp, 1.0e23_xp, &
      1.0e24_xp, 1.0e25_xp, 1.0e26_xp, 1.0e27_xp]

   !> An integer (default or 64-bit) without blanks.
   interface int_str
      module procedure int_str_default, int_str_i8
   end interface int_str

   interface
      !> femcod_decimal.c: snprintf(buffer, size, "%.*e", digits - 1, x).
      function c_decimal_e(x, digits, buffer, size) bind(c, name="femcod_decimal_e") result(length)
         import :: c_double, c_int, c_char
         real(c_double), value :: x
         integer(c_int), value :: digits, size
         character(kind=c_char), intent(out) :: buffer(*)
         integer(c_int) :: length
      end function c_decimal_e
      !> femcod_decimal.c: strtod(text, NULL).
      function c_decimal_read(text) bind(c, name="femcod_decimal_read") result(x)
         import :: c_double, c_char
         character(kind=c_char), intent(in) :: text(*)
         real(c_double) :: x
      end function c_decimal_read
   end interface

contains

   !> A decimal mantissa without trailing zeros after its point, nor a bare point
   !> ("2.500" -> "2.5", "3.000" -> "3"); text without a point is returned as it is.
   pure function without_trailing_zeros(s) result(t)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: t
      t = s
      if (index(t, ".") == 0) return
      do while (t(len(t):len(t)) == "0")
         t = t(1:len(t) - 1)
      end do
      if (t(len(t):len(t)) == ".") t = t(1:len(t) - 1)
   end function without_trailing_zeros

   pure function int_str_default(i) result(s)
      integer, intent(in) :: i
      character(len=:), allocatable :: s
      character(len=20) :: text
      integer :: length
      call integer_text(int(i, i8), text, length)
      s = text(1:length)
   end function int_str_default

   !> A 64-bit integer without blanks.
   pure function int_str_i8(i) result(s)
      integer(i8), intent(in) :: i
      character(len=:), allocatable :: s
      character(len=20) :: text
      integer :: length
      call integer_text(i, text, length)
      s = text(1:length)
   end function int_str_i8

   !> The decimal digits of `i` in text(1:length), with a sign when negative: what
   !> write '(i0)' gives, without formatted I/O and safe in a parallel region.
   pure subroutine integer_text(i, text, length)
      integer(i8), intent(in) :: i
      character(len=20), intent(out) :: text
      integer, intent(out) :: length
      character(len=20) :: reversed
      integer(i8) :: m
      integer :: n, d
      text = ""
      n = 0
      m = i
      ! Digits from the least significant, taken from a negative number so that
      ! -huge - 1 has no overflow.
      if (m > 0) m = -m
      do
         d = int(-mod(m, 10_i8))
         n = n + 1
         reversed(n:n) = achar(iachar("0") + d)
         m = m/10
         if (m == 0) exit
      end do
      length = 0
      if (i < 0) then
         text(1:1) = "-"
         length = 1
      end if
      do d = n, 1, -1
         length = length + 1
         text(length:length) = reversed(d:d)
      end do
   end subroutine integer_text

   !> A real in `es` form with `digits` significant digits.
   function real_str(x, digits) result(s)
      real(dp), intent(in) :: x
      integer, intent(in) :: digits
      character(len=:), allocatable :: s
      character(len=40) :: buf, fmt
      write(fmt, '("(es",i0,".",i0,"e3)")') digits + 8, digits - 1
      write(buf, fmt) x
      s = trim(adjustl(buf))
   end function real_str

   !> A real in fixed-point form with `decimals` digits after the point (tables).
   function fixed_str(x, decimals) result(s)
      real(dp), intent(in) :: x
      integer, intent(in) :: decimals
      character(len=:), allocatable :: s
      character(len=40) :: buf, fmt
      write(fmt, '("(f0.",i0,")")') decimals
      write(buf, fmt) x
      s = trim(adjustl(buf))
      if (s(1:1) == ".") s = "0"//s
      if (s(1:min(2, len(s))) == "-.") s = "-0"//s(2:)
   end function fixed_str

   !> The shortest decimal form of `x` that reads back to the same double: the fewest
   !> significant digits n (1 to 17) whose correctly rounded decimal reads back to `x`,
   !> written "1.5e-7" (no trailing zeros, no exponent when it is 0), or in plain
   !> positional form ("0.0025", "1200") when 1e-4 <= |x| < 1e15 and that is not longer.
   !>
   !> Each candidate is rounded and read back in extended precision (nearest_decimal,
   !> exact_decimal), and made into text only when it reads back; near a rounding tie C's
   !> snprintf "%.*e" and strtod decide (correctly rounded in glibc). Which n: if n
   !> digits read back, so do n + 1 (the (n+1)-digit rounding is at least as close to x),
   !> so the answer is found by trying 16, then 17 or 15, then bisection below 15.
   !> The smallest n never ends in 0 (n - 1 digits would read back as well), so the
   !> positional form of those digits is the one with the fewest decimals.
   function format_real(x) result(s)
      real(dp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=24) :: text
      integer :: length
      call shortest_decimal(x, text, length)
      s = text(1:length)
   end function format_real

   !> format_real's answer in text(1:length), with fixed-length buffers only: gfortran 12
   !> keeps the length of a deferred-length function result in a static variable of the
   !> caller, so a routine that calls one (int_str, without_trailing_zeros) is not safe
   !> in an OpenMP parallel region, and format_reals runs this one there.
   subroutine shortest_decimal(x, text, length)
      real(dp), intent(in) :: x
      !> The longest answer is "-d.dddddddddddddddde-ddd", 24 characters.
      character(len=24), intent(out) :: text
      integer, intent(out) :: length
      character(len=40) :: buf, good, digits, fixed
      character(kind=c_char, len=40) :: cbuf
      integer(c_int) :: clength
      integer :: n, lo, hi, mid, e, mark, k, m, nm, nd, nf, i
      logical :: negative_exponent
      text = ""
      if (x == 0) then
         text = "0"
         length = 1
         return
      end if
      ! Not a number and the infinities as numpy, pandas and Python's float() read them.
      if (x /= x) then
         text = "nan"
         length = 3
         return
      else if (.not. ieee_is_finite(x)) then
         text = trim(merge("inf ", "-inf", x > 0))
         length = len_trim(text)
         return
      end if
      ! Seventeen digits always read back: that case needs no check.
      if (reads_back(x, 16, buf)) then
         n = 16
         good = buf
         if (reads_back(x, 15, buf)) then
            n = 15
            good = buf
            lo = 1
            hi = 15
            do while (lo < hi)
               mid = (lo + hi)/2
               if (reads_back(x, mid, buf)) then
                  hi = mid
                  n = mid
                  good = buf
               else
                  lo = mid + 1
               end if
            end do
         end if
         buf = good
      else
         n = 17
         call decimal_e(x, 17, buf)
      end if
      ! buf holds "-d.ddde+XX" for n digits: the exponent e, the mantissa buf(1:nm)
      ! without trailing zeros (and without a trailing point).
      mark = index(buf, "e")
      e = 0
      negative_exponent = buf(mark + 1:mark + 1) == "-"
      do i = mark + 2, len_trim(buf)
         e = 10*e + (iachar(buf(i:i)) - iachar("0"))
      end do
      if (negative_exponent) e = -e
      nm = mark - 1
      if (index(buf(1:nm), ".") > 0) then
         do while (buf(nm:nm) == "0")
            nm = nm - 1
         end do
         if (buf(nm:nm) == ".") nm = nm - 1
      end if
      text = buf(1:nm)
      length = nm
      if (e /= 0) then
         text(length + 1:length + 1) = "e"
         length = length + 1
         if (e < 0) then
            text(length + 1:length + 1) = "-"
            length = length + 1
         end if
         m = abs(e)
         k = 1
         do while (k*10 <= m)
            k = 10*k
         end do
         do while (k >= 1)
            text(length + 1:length + 1) = achar(iachar("0") + m/k)
            length = length + 1
            m = mod(m, k)
            k = k/10
         end do
      end if
      if (abs(x) >= 1.0e-4_dp .and. abs(x) < 1.0e15_dp) then
         ! The same digits in positional form. The digits of "-d.ddd": without the sign
         ! and the point.
         k = 1
         if (buf(1:1) == "-") k = 2
         if (nm > k) then
            digits = buf(k:k)//buf(k + 2:nm)
            nd = nm - k
         else
            digits = buf(k:k)
            nd = 1
         end if
         if (e >= 0) then
            if (nd <= e + 1) then
               fixed = digits(1:nd)//repeat("0", e + 1 - nd)
               nf = e + 1
            else
               fixed = digits(1:e + 1)//"."//digits(e + 2:nd)
               nf = nd + 1
            end if
         else
            fixed = "0."//repeat("0", -e - 1)//digits(1:nd)
            nf = 1 - e + nd
         end if
         if (x < 0) then
            fixed = "-"//fixed
            nf = nf + 1
         end if
         if (nf <= length) then
            text = fixed(1:nf)
            length = nf
         end if
      end if
   end subroutine shortest_decimal

   !> format_real of every element of `x`, converted in parallel (OpenMP): element k
   !> is texts(k)(1:lengths(k)). For the large tables (a deck's heights, every contact),
   !> where the conversions are most of the writing.
   subroutine format_reals(x, texts, lengths)
      real(dp), intent(in) :: x(:)
      !> format_real's longest answer is "-d.dddddddddddddddde-ddd", 24 characters.
      character(len=24), allocatable, intent(out) :: texts(:)
      integer, allocatable, intent(out) :: lengths(:)
      integer :: k
      allocate(texts(size(x)), lengths(size(x)))
      !$omp parallel do private(k) schedule(static)
      do k = 1, size(x)
         call shortest_decimal(x(k), texts(k), lengths(k))
      end do
      !$omp end parallel do
   end subroutine format_reals

   !> Whether `x` with `digits` significant digits reads back to `x`; `buf` holds that
   !> decimal (decimal_e's form) when it does. Where the wide kind forms the decimal
   !> (nearest_decimal) and reads it back (exact_decimal, as parse_real would read its
   !> text), no text is made for a decimal that does not read back; else decimal_e and
   !> parse_real decide.
   logical function reads_back(x, digits, buf)
      real(dp), intent(in) :: x
      integer, intent(in) :: digits
      character(len=40), intent(out) :: buf
      real(dp) :: y
      logical :: ok
      integer(i8) :: q
      integer :: n, e10
      call nearest_decimal(x, digits, q, e10, ok)
      if (ok) call exact_decimal(q, e10 - digits + 1, y, ok)
      if (ok) then
         reads_back = y == abs(x)
         buf = ""
         if (reads_back) call decimal_text(x < 0, q, e10, digits, buf)
         return
      end if
      call decimal_e(x, digits, buf)
      reads_back = .false.
      n = len_trim(buf)
      if (n == 0) return
      ! parse_real refuses a decimal rounded up past the largest double (not finite) and
      ! keeps strtod's overflow from trapping under -ffpe-trap=overflow.
      call parse_real(buf(1:n), y, ok)
      reads_back = ok .and. y == x
   end function reads_back

   !> x (finite, not 0) with `ndigits` (1 to 17) significant digits in C's "%.*e" form
   !> ("-d.ddde+XX", correctly rounded, ties to even) in buf; blank if C fails. The digits
   !> are nearest_decimal's where it decides them, else C's snprintf's. glibc's printf
   !> forms every digit in multi-precision arithmetic: it was most of writing a deck or
   !> PREFIX.contacts.csv.
   subroutine decimal_e(x, ndigits, buf)
      real(dp), intent(in) :: x
      integer, intent(in) :: ndigits
      character(len=40), intent(out) :: buf
      character(kind=c_char, len=40) :: cbuf
      integer(c_int) :: length
      integer(i8) :: q
      integer :: e10
      logical :: done
      buf = ""
      call nearest_decimal(x, ndigits, q, e10, done)
      if (done) then
         call decimal_text(x < 0, q, e10, ndigits, buf)
         return
      end if
      length = c_decimal_e(x, int(ndigits, c_int), cbuf, int(len(cbuf), c_int))
      if (length <= 0 .or. length >= len(cbuf)) return
      buf = cbuf(1:length)
   end subroutine decimal_e

   !> |x| (finite, not 0) rounded to `ndigits` (1 to 17) significant digits, ties to
   !> even: q (ndigits digits) times 10**(e10 - ndigits + 1). Where 10**k that scales x to
   !> `ndigits` digits is exact in a real kind of 64 significand bits (|k| <= 27), x 10**k
   !> is formed there with one rounding (an error below 2**-64 of it) and rounded to an
   !> integer; `done` is false where it is not, and where the fraction lies within one
   !> unit of that kind of a half, where the error could decide the rounding.
   subroutine nearest_decimal(x, ndigits, q, e10, done)
      real(dp), intent(in) :: x
      integer, intent(in) :: ndigits
      integer(i8), intent(out) :: q
      integer, intent(out) :: e10
      logical, intent(out) :: done
      real(xp) :: scaled, fraction_part, low, high
      integer :: k, tries
      done = .false.
      q = 0
      e10 = 0
      if (.not. (digits(1.0_xp) >= 64 .and. ieee_is_finite(x) .and. x /= 0)) return
      e10 = floor(log10(abs(x)))
      low = powers_of_ten(ndigits - 1)
      high = powers_of_ten(ndigits)
      do tries = 1, 2
         k = ndigits - 1 - e10
         if (abs(k) > 27) exit
         if (k >= 0) then
            scaled = abs(real(x, xp))*powers_of_ten(k)
         else
            scaled = abs(real(x, xp))/powers_of_ten(-k)
         end if
         ! log10 may be one off near a power of ten: then scale once more.
         if (scaled < low) then
            e10 = e10 - 1
            cycle
         else if (scaled >= high) then
            e10 = e10 + 1
            cycle
         end if
         q = int(scaled, i8)
         fraction_part = scaled - real(q, xp)
         ! (scaled epsilon is at least one unit of the kind at `scaled`.)
         if (abs(fraction_part - 0.5_xp) <= scaled*epsilon(scaled)) exit
         if (fraction_part > 0.5_xp) q = q + 1
         if (real(q, xp) >= high) then
            q = q/10
            e10 = e10 + 1
         end if
         done = .true.
         exit
      end do
   end subroutine nearest_decimal

   !> "-d.ddde+XX": the digits of q (ndigits of them) with the point after the first,
   !> the sign when `negative`, and the exponent e10 with at least two digits.
   pure subroutine decimal_text(negative, q, e10, ndigits, buf)
      logical, intent(in) :: negative
      integer(i8), intent(in) :: q
      integer, intent(in) :: e10, ndigits
      character(len=40), intent(inout) :: buf
      character(len=20) :: q_text, e_text
      integer :: at, n, ne
      call integer_text(q, q_text, n)
      call integer_text(int(abs(e10), i8), e_text, ne)
      at = 0
      if (negative) then
         buf(1:1) = "-"
         at = 1
      end if
      buf(at + 1:at + 1) = q_text(1:1)
      at = at + 1
      if (ndigits > 1) then
         buf(at + 1:at + ndigits) = "."//q_text(2:ndigits)
         at = at + ndigits
      end if
      buf(at + 1:at + 2) = merge("e-", "e+", e10 < 0)
      at = at + 2
      if (ne < 2) then
         buf(at + 1:at + 1) = "0"
         at = at + 1
      end if
      buf(at + 1:at + ne) = e_text(1:ne)
   end subroutine decimal_text

   !> Parse a real token: [sign] digits [. digits] [(e|E|d|D) [sign] digits], at least
   !> one mantissa digit. NaN, Inf, repeat counts and overflow are refused. The result is
   !> the correctly rounded double (round half to even), as Fortran's READ and C's strtod
   !> give it: exactly by `exact_decimal` for up to 18 significant digits and a decimal
   !> exponent within 27 of them (every value femcod writes), else by strtod.
   subroutine parse_real(token, value, ok)
      character(len=*), intent(in) :: token
      real(dp), intent(out) :: value
      logical, intent(out) :: ok
      character(kind=c_char, len=64) :: short
      character(len=:), allocatable :: long
      integer :: i, n, ndig, mark, nsig, d, scale10, power, exp_sign
      integer(i8) :: significand, chunk
      logical :: halting, negative, fast, in_fraction, all_digits
      value = 0
      ok = .false.
      n = len(token)
      i = 1
      mark = 0
      if (n == 0) return
      negative = token(1:1) == "-"
      if (token(i:i) == "+" .or. token(i:i) == "-") i = i + 1
      ! The digits, gathered into `significand` (leading zeros skipped) while there are
      ! at most 18; value = significand * 10**(scale10 + the exponent).
      ndig = 0
      nsig = 0
      significand = 0
      scale10 = 0
      fast = .true.
      in_fraction = .false.
      do while (i <= n)
         ! Eight digits at a time after the first significant one (femcod_bytes), while
         ! the significand stays within 18 digits.
         if (nsig >= 1 .and. nsig <= 10 .and. n - i >= 7) then
            call eight_digits(token(i:i + 7), chunk, all_digits)
            if (all_digits) then
               significand = significand*100000000_i8 + chunk
               nsig = nsig + 8
               ndig = ndig + 8
               if (in_fraction) scale10 = scale10 - 8
               i = i + 8
               cycle
            end if
         end if
         d = iachar(token(i:i)) - iachar("0")
         if (d >= 0 .and. d <= 9) then
            ndig = ndig + 1
            if (nsig < 18) then
               if (nsig > 0 .or. d > 0) then
                  significand = 10*significand + d
                  nsig = nsig + 1
               end if
               if (in_fraction) scale10 = scale10 - 1
            else
               fast = .false.
            end if
         else if (token(i:i) == "." .and. .not. in_fraction) then
            in_fraction = .true.
         else
            exit
         end if
         i = i + 1
      end do
      if (ndig == 0) return
      power = 0
      if (i <= n) then
         if (index("eEdD", token(i:i)) == 0) return
         mark = i
         i = i + 1
         exp_sign = 1
         if (i <= n) then
            if (token(i:i) == "+" .or. token(i:i) == "-") then
               if (token(i:i) == "-") exp_sign = -1
               i = i + 1
            end if
         end if
         if (i > n) return
         do while (i <= n)
            if (.not. is_digit(token(i:i))) return
            if (power < 100000) power = 10*power + (iachar(token(i:i)) - iachar("0"))
            i = i + 1
         end do
         power = exp_sign*power
      end if
      if (fast) call exact_decimal(significand, scale10 + power, value, fast)
      if (fast) then
         if (negative) value = -value
         ok = .true.
         return
      end if
      ! C's strtod (correctly rounded like Fortran's READ, a tenth of its time) on a
      ! NUL-terminated copy, the Fortran exponent letter d made e. Only a literal with an
      ! exponent or of 300 characters can overflow: that must give a message, not a trap
      ! under -ffpe-trap=overflow.
      halting = .false.
      if (mark > 0 .or. n >= 300) then
         call ieee_get_halting_mode(ieee_overflow, halting)
         if (halting) call ieee_set_halting_mode(ieee_overflow, .false.)
      end if
      if (n < len(short)) then
         short(1:n) = token
         if (mark > 0) short(mark:mark) = "e"
         short(n + 1:n + 1) = c_null_char
         value = c_decimal_read(short)
      else
         long = token//c_null_char
         if (mark > 0) long(mark:mark) = "e"
         value = c_decimal_read(long)
      end if
      if (mark > 0 .or. n >= 300) then
         call ieee_set_flag(ieee_overflow, .false.)
         if (halting) call ieee_set_halting_mode(ieee_overflow, .true.)
      end if
      ok = ieee_is_finite(value)
   end subroutine parse_real

   !> The double nearest to m * 10**e (m >= 0, at most 18 digits; round half to even),
   !> exactly, where |e| <= 27 and the compiler has a real kind of at least 64 significand
   !> bits (x87's 80-bit format in gfortran on x86-64; quadruple precision elsewhere):
   !> there m and 10**|e| (5**27 < 2**64) are exact, so m * 10**e or m / 10**-e is
   !> rounded once to that kind, then once to double. Two roundings give the nearest
   !> double unless the first lands exactly halfway between two doubles (a halfway point
   !> has 54 bits, so it is in the wider kind: any nearer result would be it); `done` is
   !> false then, and where the conditions fail, for strtod to decide. glibc's strtod
   !> takes a deck's 17-digit heights through multi-precision arithmetic: it was a third of
   !> the time reading a 2048^2 deck.
   elemental subroutine exact_decimal(m, e, x, done)
      integer(i8), intent(in) :: m
      integer, intent(in) :: e
      real(dp), intent(out) :: x
      logical, intent(out) :: done
      real(xp) :: wide, beyond
      x = 0
      done = digits(1.0_xp) >= 64 .and. abs(e) <= 27
      if (.not. done) return
      if (e >= 0) then
         wide = real(m, xp)*powers_of_ten(e)
      else
         wide = real(m, xp)/powers_of_ten(-e)
      end if
      x = real(wide, dp)
      if (real(x, xp) == wide) return
      ! wide lies strictly within half a unit of x; it is the midpoint of x and its
      ! neighbour exactly when reflecting x about wide, 2 wide - x (exact in the wider
      ! kind: x and wide share their binade up to a unit of x), gives a double.
      beyond = 2*wide - real(x, xp)
      done = real(real(beyond, dp), xp) /= beyond
   end subroutine exact_decimal

   !> Parse an integer token: [sign] digits, within the range of a default integer.
   subroutine parse_integer(token, value, ok)
      character(len=*), intent(in) :: token
      integer, intent(out) :: value
      logical, intent(out) :: ok
      integer :: i, i0, ios
      integer(i8) :: wide
      value = 0
      ok = .false.
      if (len(token) == 0 .or. len(token) > 18) return
      i0 = 1
      if (token(1:1) == "+" .or. token(1:1) == "-") i0 = 2
      if (i0 > len(token)) return
      do i = i0, len(token)
         if (.not. is_digit(token(i:i))) return
      end do
      read(token, *, iostat=ios) wide
      if (ios /= 0 .or. abs(wide) > huge(value)) return
      value = int(wide)
      ok = .true.
   end subroutine parse_integer

   pure logical function is_digit(c)
      character(len=1), intent(in) :: c
      is_digit = c >= "0" .and. c <= "9"
   end function is_digit

   !> A JSON number: the shortest decimal that reads back to `x` (format_real); null
   !> for NaN and infinities, which JSON cannot hold.
   function json_number(x) result(j)
      real(dp), intent(in) :: x
      character(len=:), allocatable :: j
      if (.not. ieee_is_finite(x) .or. x /= x) then
         j = "null"
      else
         j = format_real(x)
      end if
   end function json_number

   !> `v` with `digits` significant digits for people to read: plain decimals from 1e-3
   !> to below 1e6 ("100", "0.0526049"), else "2.5e-7" and "1.2e+9"; no trailing zeros.
   function sig_str(v, digits) result(s)
      real(dp), intent(in) :: v
      integer, intent(in) :: digits
      character(len=:), allocatable :: s
      character(len=40) :: buf
      integer :: e, mark
      if (v == 0) then
         s = "0"
         return
      end if
      if (.not. ieee_is_finite(v)) then
         ! Infinity or NaN as the processor writes it, never a failed read below.
         write(buf, '(g0)') v
         s = trim(adjustl(buf))
         return
      end if
      write(buf, '(es40.'//int_str(digits - 1)//'e3)') v
      ! The exponent after rounding to `digits` (9.9996 becomes 1.000E+001).
      mark = index(buf, "E")
      read(buf(mark + 1:), *) e
      if (e >= -3 .and. e < 6) then
         write(buf, '(f0.'//int_str(max(0, digits - 1 - e))//')') v
         s = without_trailing_zeros(trim(adjustl(buf)))
         if (s(1:1) == ".") s = "0"//s
         if (len(s) > 1) then
            if (s(1:2) == "-.") s = "-0"//s(2:)
         end if
      else
         s = without_trailing_zeros(trim(adjustl(buf(1:mark - 1))))
         if (e < 0) then
            s = s//"e-"//int_str(-e)
         else
            s = s//"e+"//int_str(e)
         end if
      end if
   end function sig_str
end module femcod_decimal
