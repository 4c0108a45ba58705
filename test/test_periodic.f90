!> Periodic surfaces: the periodic Love kernel against a sum over its images in real
!> space, the cyclic convolution against a direct sum.
module test_periodic
   use femcod_kinds, only: dp
   use femcod_love, only: love_influence
   use femcod_love_periodic, only: periodic_love_spectrum, periodic_offset_table
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_apply_single, &
      convolution_free, inverse_kernel_taps
   use femcod_random, only: random_stream, seed_stream, uniform
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_periodic

   real(dp), parameter :: pi = 3.141592653589793238462643383279502884_dp

contains

   subroutine collect_periodic(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("kernel: differences equal a real-space sum over 401^2 images (NP 8, 9)", test_image_sum), &
         new_unittest("cyclic FFT convolution equals the direct periodic sum (NP 7, 8, 33)", test_cyclic), &
         new_unittest("inverse taps on the periodic grid invert its spectrum off zero frequency", test_taps) &
         ]
   end subroutine collect_periodic

   !> K(p, q) - K(0, 0) of periodic_offset_table (computed in Fourier space) against the
   !> same difference summed in real space over the images X = NP (m, n), |m|, |n| <= R,
   !>     sum_X [I(x + X) - I(X)],
   !> with femcod_love's pixel influence I. The images beyond R add, to second order in
   !> x (the first cancels on the square),
   !>     |x|^2/4 sum_{X outside} 1/|X|^3 = |x|^2/4 * 4 sqrt(2)/((R + 1/2) NP^3),
   !> the integral of 1/r^3 outside the square of side 2R + 1 (the cells of the lattice
   !> outside); the next terms are O(|x|^4/(R^3 NP^5)). With R = 200 that leaves
   !> 7e-10 to 9e-10 (measured; 8e-11 to 1.1e-10 at R = 400, the R^-3 of the terms left
   !> out), against the kernel's largest value I(0, 0) = 3.53.
   subroutine test_image_sum(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: r = 200
      real(dp), allocatable :: k(:, :)
      real(dp) :: direct, tail, worst
      integer :: np, p, q, m, n, c
      integer, parameter :: sizes(2) = [8, 9]
      do c = 1, size(sizes)
         np = sizes(c)
         if (allocated(k)) deallocate(k)
         allocate(k(0:np - 1, 0:np - 1))
         k(:, :) = periodic_offset_table(np)
         call check(error, abs(sum(k)) < 1.0e-12_dp, "NP "//to_string(np)//": the kernel's sum is not 0: "// &
            to_string(sum(k)))
         if (allocated(error)) return
         worst = 0
         do q = 0, np/2
            do p = 0, np/2
               direct = 0
               !$omp parallel do reduction(+:direct) private(m)
               do n = -r, r
                  do m = -r, r
                     direct = direct + (love_influence(p + m*np, q + n*np) - love_influence(m*np, n*np))
                  end do
               end do
               !$omp end parallel do
               tail = real(p*p + q*q, dp)*sqrt(2.0_dp)/((r + 0.5_dp)*real(np, dp)**3)
               worst = max(worst, abs((k(p, q) - k(0, 0)) - (direct + tail)))
            end do
         end do
         call check(error, worst < 2.0e-9_dp, "NP "//to_string(np)//": largest difference "//to_string(worst))
         if (allocated(error)) return
      end do
   end subroutine test_image_sum

   !> convolution_setup(periodic) applied to random forces equals the cyclic sum
   !> sum_kl K(mod(i - k, NP), mod(j - l, NP)) F(k, l) over the periodic table, in
   !> double (1e-12 of the largest value) and float32 (1e-5).
   subroutine test_cyclic(error)
      type(error_type), allocatable, intent(out) :: error
      type(love_convolution) :: conv
      type(random_stream) :: rng
      real(dp), allocatable :: table(:, :), f(:, :), fast(:, :), fast32(:, :), direct(:, :)
      integer :: np, i, j, k, l, c
      integer, parameter :: sizes(3) = [7, 8, 33]
      call seed_stream(rng, 42)
      do c = 1, size(sizes)
         np = sizes(c)
         if (allocated(table)) deallocate(table)
         allocate(table(0:np - 1, 0:np - 1))
         table(:, :) = periodic_offset_table(np)
         allocate(f(np, np), fast(np, np), fast32(np, np), direct(np, np))
         do j = 1, np
            do i = 1, np
               call uniform(rng, f(i, j))
            end do
         end do
         direct = 0
         do l = 1, np
            do k = 1, np
               do j = 1, np
                  do i = 1, np
                     direct(i, j) = direct(i, j) + table(modulo(i - k, np), modulo(j - l, np))*f(k, l)
                  end do
               end do
            end do
         end do
         call convolution_setup(conv, table, single=.true., periodic=.true.)
         call convolution_apply(conv, f, fast)
         call convolution_apply_single(conv, f, fast32)
         call convolution_free(conv)
         call check(error, maxval(abs(fast - direct)) < 1.0e-12_dp*maxval(abs(direct)), "NP "//to_string(np)// &
            ": double differs by "//to_string(maxval(abs(fast - direct))))
         if (allocated(error)) return
         call check(error, maxval(abs(fast32 - direct)) < 1.0e-5_dp*maxval(abs(direct)), "NP "//to_string(np)// &
            ": float32 differs by "//to_string(maxval(abs(fast32 - direct))))
         if (allocated(error)) return
         deallocate(f, fast, fast32, direct)
      end do
   end subroutine test_cyclic

   !> The 13-point taps of the periodic grid against a direct DFT of the pseudo-inverse:
   !> tap(a, b) = 1/NP^2 sum over k /= 0 of cos(2 pi (a k1 + b k2)/NP) / S(k) with the
   !> spectrum S of periodic_love_spectrum (mirrored to the whole grid).
   subroutine test_taps(error)
      type(error_type), allocatable, intent(out) :: error
      type(love_convolution) :: conv
      real(dp), allocatable :: s(:, :)
      real(dp) :: taps(0:2, 0:2), expected
      logical :: ok
      integer :: np, a, b, k1, k2, c
      integer, parameter :: sizes(2) = [8, 9]
      do c = 1, size(sizes)
         np = sizes(c)
         if (allocated(s)) deallocate(s)
         allocate(s(0:np/2, 0:np/2))
         s(:, :) = periodic_love_spectrum(np)
         call convolution_setup(conv, periodic_offset_table(np), periodic=.true.)
         call inverse_kernel_taps(conv, taps, ok)
         call convolution_free(conv)
         call check(error, ok, "NP "//to_string(np)//": no taps")
         if (allocated(error)) return
         do b = 0, 2
            do a = 0, 2
               expected = 0
               do k2 = 0, np - 1
                  do k1 = 0, np - 1
                     if (k1 == 0 .and. k2 == 0) cycle
                     expected = expected + cos(2*pi*real(a*k1 + b*k2, dp)/np)/s(min(k1, np - k1), min(k2, np - k2))
                  end do
               end do
               expected = expected/real(np, dp)**2
               call check(error, abs(taps(a, b) - expected) < 1.0e-12_dp*abs(taps(0, 0)), "NP "//to_string(np)// &
                  ": tap ("//to_string(a)//", "//to_string(b)//") "//to_string(taps(a, b))//" vs "//to_string(expected))
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_taps

end module test_periodic
