!> Surface generators, transforms and the verification decks of input/.
module test_surfaces
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: write_deck, read_deck
   use femcod_problem, only: contact_problem
   use femcod_surfaces, only: circle_punch, square_punch, sphere_cap, wm_terms, self_affine_surface, remove_plane, &
      rms_height, sinusoid_surface, downsample_average, downsample_subsample
   use femcod_generate, only: scene_spec, build_problem, verification_spec, VERIFICATION_DECKS
   use femcod_heights, only: read_heights
   use femcod_scene, only: initial_gaps, flip_upper, rms_slope
   use femcod_random, only: random_stream, seed_stream, uniform, advance_stream
   use, intrinsic :: iso_fortran_env, only: int64
   use test_support, only: write_text, read_text, scratch_path, contains_text
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_surfaces

contains

   subroutine collect_surfaces(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("circle punch: 21, 189, 1701 pixels (Table 4.1), 90-degree symmetric", test_circle), &
         new_unittest("square punch: 1, 9, 81, 729 pixels (Table 4.2)", test_square), &
         new_unittest("sphere heights", test_sphere), &
         new_unittest("Weierstrass-Mandelbrot terms, eq. 3.7: 18 and 5", test_wm_terms), &
         new_unittest("self-affine surface: rms, mean, reproducible", test_self_affine), &
         new_unittest("self-affine surface with a cutoff: no waves below it, the same ones above", &
            test_self_affine_cutoff), &
         new_unittest("random stream: a jump of n is n draws (0 to 10^5 + 7)", test_stream_jump), &
         new_unittest("plane removal and down-sampling", test_transforms), &
         new_unittest("ASCII matrix: comments, errors", test_matrix), &
         new_unittest("flip and initial gaps (Fig. B.1)", test_gaps), &
         new_unittest("rms slope: a tilted plane and a sine, in closed form", test_rms_slope), &
         new_unittest("input/ decks are what mkdeck generates", test_input_decks), &
         new_unittest("input/ decks hold the thesis' scenes (closed forms, not the generator)", test_deck_scenes) &
         ]
   end subroutine collect_surfaces

   subroutine test_circle(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: m, npunch, np
      real(dp), allocatable :: z(:, :)
      type(status_type) :: status
      integer, parameter :: expected(3) = [21, 189, 1701]
      integer :: k
      do k = 1, 3
         m = 3**(k - 1)
         np = 11*m
         allocate(z(np, np))
         call circle_punch(np, 1.0_dp/m, 21.0_dp, 1.0_dp, z, npunch, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         ! Table 4.1 / Fig. 4.10: 21, 189 and 1701 pixels.
         call check(error, npunch, expected(k), "punch pixels at d = 1/"//to_string(m))
         if (allocated(error)) return
         call check(error, count(z > 0), expected(k))
         if (allocated(error)) return
         ! Symmetric under rotation by 90 degrees: z(i,j) = z(j, np+1-i).
         call check(error, all(z == transpose(z(np:1:-1, :))), "90-degree rotation symmetry")
         if (allocated(error)) return
         deallocate(z)
      end do
      ! At d = 1/3 Table 4.1 has 189 pixels; the whole rings p^2 + q^2 < 61 hold 185 (counted
      ! by hand), so exactly 4 of the 8 pixels with p^2 + q^2 = 61 are in the punch.
      allocate(z(33, 33))
      call circle_punch(33, 1.0_dp/3, 21.0_dp, 1.0_dp, z, npunch, status)
      call check(error, count([z(17 + 5, 17 + 6), z(17 + 6, 17 + 5), z(17 - 5, 17 + 6), z(17 - 6, 17 + 5), &
         z(17 + 5, 17 - 6), z(17 + 6, 17 - 5), z(17 - 5, 17 - 6), z(17 - 6, 17 - 5)] > 0), 4, "ring sqrt(61)/3 split")
   end subroutine test_circle

   subroutine test_square(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: k, np
      real(dp), allocatable :: z(:, :)
      type(status_type) :: status
      do k = 1, 4
         np = 3**k
         allocate(z(np, np))
         call square_punch(np, 1.0_dp, z, status)
         call check(error, count(z > 0), (np/3)**2, "punch pixels at NP = "//to_string(np))
         if (allocated(error)) return
         deallocate(z)
      end do
      allocate(z(10, 10))
      call square_punch(10, 1.0_dp, z, status)
      call check(error, status%code, 3, "NP not divisible by 3 is refused")
   end subroutine test_square

   subroutine test_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: z(31, 31)
      call sphere_cap(31, 1.0_dp, 15.0_dp, z)
      ! Apex at the centre pixel (16,16): 15 nm; (16,16+9): sqrt(225-81) = 12 nm; corner outside: 0.
      call check(error, z(16, 16), 15.0_dp, thr=1.0e-14_dp)
      if (allocated(error)) return
      call check(error, z(16, 25), 12.0_dp, thr=1.0e-14_dp)
      if (allocated(error)) return
      call check(error, z(1, 1), 0.0_dp)
   end subroutine test_sphere

   subroutine test_wm_terms(error)
      type(error_type), allocatable, intent(out) :: error
      ! Thesis after eq. 3.7: 1 nm to 1 um needs 18 terms for gamma = 1.5 and 5 for gamma = 5.
      call check(error, wm_terms(1000.0_dp, 1.0_dp, 1.5_dp), 18)
      if (allocated(error)) return
      call check(error, wm_terms(1000.0_dp, 1.0_dp, 5.0_dp), 5)
   end subroutine test_wm_terms

   !> advance_stream(n) against n calls of uniform (the recursion itself): the next
   !> draws agree exactly, for jumps of 0, 1, 2, 3, 1000 and 100007 (more than 2^16,
   !> so that mulmod's two halves both carry), from two seeds.
   subroutine test_stream_jump(error)
      type(error_type), allocatable, intent(out) :: error
      integer(int64), parameter :: jumps(6) = [0_int64, 1_int64, 2_int64, 3_int64, 1000_int64, 100007_int64]
      type(random_stream) :: drawn, jumped
      real(dp) :: u, v
      integer(int64) :: k
      integer :: j, seed, d
      do seed = 1, 2
         do j = 1, size(jumps)
            call seed_stream(drawn, 1000*seed + 7)
            jumped = drawn
            do k = 1, jumps(j)
               call uniform(drawn, u)
            end do
            call advance_stream(jumped, jumps(j))
            do d = 1, 3
               call uniform(drawn, u)
               call uniform(jumped, v)
               call check(error, u == v, "seed "//to_string(seed)//", jump "//to_string(int(jumps(j)))//", draw "// &
                  to_string(d)//": "//to_string(v)//" against "//to_string(u))
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_stream_jump

   subroutine test_self_affine(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: z(64, 64), w(64, 64)
      call self_affine_surface(64, 2.0_dp, 0.8_dp, 3.0_dp, 5, z)
      call check(error, rms_height(z), 3.0_dp, rel=.true., thr=1.0e-12_dp)
      if (allocated(error)) return
      call check(error, abs(sum(z))/size(z) < 1.0e-12_dp, "zero mean")
      if (allocated(error)) return
      call self_affine_surface(64, 2.0_dp, 0.8_dp, 3.0_dp, 5, w)
      call check(error, all(z == w), "same seed, same surface")
      if (allocated(error)) return
      call self_affine_surface(64, 2.0_dp, 0.8_dp, 3.0_dp, 6, w)
      call check(error, any(z /= w), "another seed, another surface")
   end subroutine test_self_affine

   !> A cutoff of 8 nm on 64 pixels of 2 nm: a discrete Fourier transform taken here (a
   !> dense matrix product, not FFTW) has no power at |q| > 2 pi/8, and below it the same
   !> coefficients as the surface without the cutoff up to one factor (the rms scaling).
   subroutine test_self_affine_cutoff(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: N = 64
      real(dp), parameter :: D = 2, CUT = 8, PI = acos(-1.0_dp)
      real(dp) :: z(N, N), w(N, N), q, ratio
      complex(dp) :: e(N, N), zc(N, N), wc(N, N)
      integer :: i, j, fi, fj
      logical :: kept(N, N)
      call self_affine_surface(N, D, 0.8_dp, 3.0_dp, 5, z, cutoff=CUT)
      call self_affine_surface(N, D, 0.8_dp, 3.0_dp, 5, w)
      call check(error, rms_height(z), 3.0_dp, rel=.true., thr=1.0e-12_dp)
      if (allocated(error)) return
      do j = 1, N
         do i = 1, N
            e(i, j) = exp(cmplx(0.0_dp, -2*PI*(i - 1)*(j - 1)/real(N, dp), dp))
         end do
      end do
      zc = matmul(e, matmul(cmplx(z, 0.0_dp, dp), transpose(e)))
      wc = matmul(e, matmul(cmplx(w, 0.0_dp, dp), transpose(e)))
      do j = 1, N
         fj = j - 1
         if (fj > N/2) fj = fj - N
         do i = 1, N
            fi = i - 1
            if (fi > N/2) fi = fi - N
            q = 2*PI*sqrt(real(fi**2 + fj**2, dp))/(N*D)
            kept(i, j) = q <= 2*PI/CUT*(1 + 1.0e-12_dp) .and. (fi /= 0 .or. fj /= 0)
            if (.not. kept(i, j) .and. (fi /= 0 .or. fj /= 0)) then
               call check(error, abs(zc(i, j)) < 1.0e-10_dp*N*N, "a wave below the cutoff: |Z| "// &
                  to_string(abs(zc(i, j)))//" at ("//to_string(fi)//", "//to_string(fj)//")")
               if (allocated(error)) return
            end if
         end do
      end do
      call check(error, count(kept) > 100, "modes kept: "//to_string(count(kept)))
      if (allocated(error)) return
      ratio = abs(zc(2, 1))/abs(wc(2, 1))
      call check(error, maxval(abs(zc - ratio*wc), mask=kept) < 1.0e-9_dp*maxval(abs(zc)), &
         "the kept waves are the uncut surface's, scaled by "//to_string(ratio))
   end subroutine test_self_affine_cutoff

   subroutine test_transforms(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: z(8, 8), s(8, 8)
      real(dp), allocatable :: w(:, :)
      integer :: i, j
      call sinusoid_surface(8, 1.0_dp, 1.0_dp, 10.0_dp, s)
      do j = 1, 8
         do i = 1, 8
            z(i, j) = 5 + 0.3_dp*i - 0.7_dp*j
         end do
      end do
      call remove_plane(z)
      call check(error, maxval(abs(z)) < 1.0e-13_dp, "an exact plane is removed completely")
      if (allocated(error)) return
      z = s + z
      w = downsample_subsample(z)
      call check(error, size(w, 1) == 4 .and. w(2, 3) == z(3, 5), "subsample keeps odd/odd pixels")
      if (allocated(error)) return
      w = downsample_average(z)
      call check(error, w(2, 3), (z(3, 5) + z(4, 5) + z(3, 6) + z(4, 6))/4, thr=1.0e-15_dp)
   end subroutine test_transforms

   subroutine test_matrix(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: z(:, :)
      type(status_type) :: status
      character(len=*), parameter :: nl = new_line("a")
      call write_text(scratch_path("m.txt"), "# Channel: Height"//nl//"# Unit: nm"//nl//"1"//achar(9)//"2"//nl// &
         "3 4"//achar(13)//nl)
      call read_heights(scratch_path("m.txt"), z, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call check(error, z(1, 2) == 2 .and. z(2, 1) == 3, "row i, column j as in the file")
      if (allocated(error)) return
      call write_text(scratch_path("m.txt"), "1 2"//nl//"3"//nl)
      call read_heights(scratch_path("m.txt"), z, status)
      call check(error, status%code == 3 .and. contains_text(status%message, ":2:"), "ragged row: "//status%message)
      if (allocated(error)) return
      status%code = 0
      call write_text(scratch_path("m.txt"), "1 2"//nl//"3 x"//nl)
      call read_heights(scratch_path("m.txt"), z, status)
      call check(error, status%code == 3 .and. contains_text(status%message, ":2:"), "bad number: "//status%message)
   end subroutine test_matrix

   !> kappa's slope scale (model/femcod_scene's rms_slope), against closed forms: a plane
   !> tilted by s along the rows and t along the columns has forward differences s d and
   !> t d at every pair, h'_rms = sqrt(s^2 + t^2) on the free surface; the sine
   !> h = A sin(2 pi i / N) on a periodic cell has differences 2 A cos(...) sin(pi/N),
   !> whose mean square over a period is 2 A^2 sin^2(pi/N): h'_rms = sqrt(2) A sin(pi/N)/d.
   subroutine test_rms_slope(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 24
      real(dp), parameter :: d = 2.5_dp, s = 0.3_dp, t = -0.7_dp, a = 1.9_dp
      real(dp) :: g(n, n), expected
      integer :: i, j
      do j = 1, n
         do i = 1, n
            g(i, j) = s*i*d + t*j*d
         end do
      end do
      call check(error, abs(rms_slope(g, d, .false.) - sqrt(s**2 + t**2)) < 1e-13_dp, "tilted plane: "// &
         to_string(rms_slope(g, d, .false.)))
      if (allocated(error)) return
      do j = 1, n
         do i = 1, n
            g(i, j) = a*sin(2*acos(-1.0_dp)*i/n)
         end do
      end do
      expected = sqrt(2.0_dp)*a*sin(acos(-1.0_dp)/n)/d
      call check(error, abs(rms_slope(g, d, .true.) - expected) < 1e-13_dp*expected, "periodic sine: "// &
         to_string(rms_slope(g, d, .true.))//" against "//to_string(expected))
      if (allocated(error)) return
      ! The sine transposed: the same slope along the other direction.
      call check(error, abs(rms_slope(transpose(g), d, .true.) - expected) < 1e-13_dp*expected, "transposed sine")
   end subroutine test_rms_slope

   subroutine test_gaps(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: lower(2, 2), upper(2, 2), g(4)
      lower = reshape([0.0_dp, 1.0_dp, 0.5_dp, 0.0_dp], [2, 2])   ! lower(1,1)=0 (2,1)=1 (1,2)=0.5 (2,2)=0
      upper = reshape([2.0_dp, 0.0_dp, 0.0_dp, 3.0_dp], [2, 2])   ! upper(1,1)=2 (2,1)=0 (1,2)=0 (2,2)=3
      ! Facing upper: row 1 <- upper row 2 = [0, 3]; row 2 <- upper row 1 = [2, 0].
      ! Sums: (1,1) 0+0=0, (1,2) 0.5+3=3.5, (2,1) 1+2=3, (2,2) 0+0=0; max 3.5.
      g = initial_gaps(lower, upper)
      call check(error, all(g == [3.5_dp, 0.0_dp, 0.5_dp, 3.5_dp]), "gaps row-wise")
      if (allocated(error)) return
      call check(error, all(flip_upper(upper) == reshape([0.0_dp, 2.0_dp, 3.0_dp, 0.0_dp], [2, 2])), "flip")
   end subroutine test_gaps

   subroutine test_input_decks(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(status_type) :: status
      character(len=:), allocatable :: path, fresh, kept
      integer :: k
      do k = 1, size(VERIFICATION_DECKS)
         call verification_spec(trim(VERIFICATION_DECKS(k)), spec, status)
         call build_problem(spec, deck, status)
         path = scratch_path(trim(VERIFICATION_DECKS(k))//".deck")
         call write_deck(path, deck, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         fresh = read_text(path)
         kept = read_text("input/"//trim(VERIFICATION_DECKS(k))//".deck")
         call check(error, len(kept) > 0 .and. fresh == kept, "input/"//trim(VERIFICATION_DECKS(k))// &
            ".deck matches 'femcod mkdeck --verification "//trim(VERIFICATION_DECKS(k))//"'")
         if (allocated(error)) return
      end do
   end subroutine test_input_decks
   !> The decks of input/ against the scenes the thesis describes, rebuilt here from their
   !> definitions and not from femcod's generator (issue 34: the test above compares the
   !> decks with the generator's own output, a golden file the code wrote):
   !>  - Table 4.1: NP = 11 m, d = 1/m nm, the 21 m^2 pixels nearest the centre (21 nm^2,
   !>    R = 2.5 nm) raised by R on the upper body (of a ring at the cut-off distance, any);
   !>  - Table 4.2: NP = 3 m, d = 30/(3m) nm, the central m x m pixels (a 10 nm square in a
   !>    30 nm region) raised by 10 nm;
   !>  - Figs. 4.14-4.16: NP = ceil(30/d), z = sqrt(R^2 - r^2) for r < R = 15 nm from the
   !>    grid centre, 0 beyond; MAXCONT the pixels within 10 nm;
   !>  - the rough deck: NP = 32, d = 10 nm, rms 3 nm about its mean, a flat rigid upper;
   !> every deck: E = 200 GPa, nu = 0.25, the rigid body and elements 1e5 times stiffer
   !> (section 4.4), and a flat lower body under the punches and spheres.
   subroutine test_deck_scenes(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      real(dp), allocatable :: want(:, :), r2(:, :)
      real(dp) :: c, d, mean, rms
      integer :: k, m, np, i, j, n
      character(len=:), allocatable :: name
      do k = 1, size(VERIFICATION_DECKS)
         name = trim(VERIFICATION_DECKS(k))
         call read_deck("input/"//name//".deck", deck, status)
         call check(error, status%code, 0, name//": "//status%message)
         if (allocated(error)) return
         call check(error, all(deck%young == [200.0_dp, 2.0e7_dp, 2.0e7_dp]) .and. all(deck%poisson == 0.25_dp), &
            name//": E = 200 GPa, nu = 0.25, rigid body and elements 1e5 times stiffer")
         if (allocated(error)) return
         np = deck%np
         d = deck%pixel
         c = (np + 1)/2.0_dp
         if (allocated(r2)) deallocate(r2)
         allocate(r2(np, np))
         do j = 1, np
            do i = 1, np
               r2(i, j) = ((i - c)**2 + (j - c)**2)*d**2
            end do
         end do
         want = 0*r2
         if (index(name, "circle_punch_d") == 1) then
            read(name(15:), *) m
            call check(error, np == 11*m .and. abs(d - 1.0_dp/m) <= 1e-15_dp, name//": NP = 11 m, d = 1/m")
            if (allocated(error)) return
            ! The 21 m^2 nearest pixels: all nearer than the (21 m^2)-th distance, none
            ! farther; a ring at exactly that distance may be cut (its choice is the
            ! generator's), so there the deck's pixels are taken as they are if raised by R.
            n = 21*m*m
            where (r2 < nth_distance(r2, n)) want = 2.5_dp
            where (r2 == nth_distance(r2, n) .and. (deck%upper == 0 .or. deck%upper == 2.5_dp)) want = deck%upper
            call check(error, count(deck%upper > 0), n, name//": 21 m^2 pixels raised")
            if (allocated(error)) return
         else if (index(name, "square_punch_n") == 1) then
            read(name(15:), *) m
            call check(error, np == 3*m .and. abs(d - 10.0_dp/m) <= 1e-14_dp, name//": NP = 3 m, d = 30/(3 m)")
            if (allocated(error)) return
            want(m + 1:2*m, m + 1:2*m) = 10
         else if (index(name, "sphere_d") == 1) then
            call check(error, np == ceiling(30/d - 1e-9_dp), name//": NP d covers 30 nm")
            if (allocated(error)) return
            where (r2 < 15.0_dp**2) want = sqrt(15.0_dp**2 - r2)
            call check(error, deck%maxcont, count(r2 < 10.0_dp**2), name//": MAXCONT = pixels within 10 nm")
            if (allocated(error)) return
         else
            call check(error, np == 32 .and. d == 10 .and. all(deck%upper == 0), name//": 32 x 32, 10 nm, flat upper")
            if (allocated(error)) return
            mean = sum(deck%lower)/size(deck%lower)
            rms = sqrt(sum((deck%lower - mean)**2)/size(deck%lower))
            call check(error, rms, 3.0_dp, rel=.true., thr=1e-12_dp, message=name//": rms 3 nm")
            cycle
         end if
         call check(error, all(deck%lower == 0), name//": a flat lower body")
         if (allocated(error)) return
         call check(error, maxval(abs(deck%upper - want)) <= 1e-12_dp*maxval(want), name//": the upper surface "// &
            "differs from its definition by "//to_string(maxval(abs(deck%upper - want)))//" nm")
         if (allocated(error)) return
      end do
   contains
      !> The n-th smallest of the values (by a sort of a copy).
      real(dp) function nth_distance(values, n) result(v)
         real(dp), intent(in) :: values(:, :)
         integer, intent(in) :: n
         real(dp), allocatable :: flat(:)
         integer :: a, b
         real(dp) :: t
         flat = reshape(values, [size(values)])
         do a = 2, size(flat)
            t = flat(a)
            b = a - 1
            do while (b >= 1)
               if (flat(b) <= t) exit
               flat(b + 1) = flat(b)
               b = b - 1
            end do
            flat(b + 1) = t
         end do
         v = flat(n)
      end function nth_distance
   end subroutine test_deck_scenes
end module test_surfaces
