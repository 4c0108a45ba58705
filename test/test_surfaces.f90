!> Surface generators, transforms and the verification decks of input/.
module test_surfaces
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: write_deck
   use femcod_problem, only: contact_problem
   use femcod_surfaces, only: circle_punch, square_punch, sphere_cap, wm_terms, self_affine_surface, remove_plane, &
      rms_height, sinusoid_surface, downsample_average, downsample_subsample
   use femcod_generate, only: scene_spec, build_problem, verification_spec, VERIFICATION_DECKS
   use femcod_heights, only: read_heights
   use femcod_scene, only: initial_gaps, flip_upper
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
         new_unittest("plane removal and down-sampling", test_transforms), &
         new_unittest("ASCII matrix: comments, errors", test_matrix), &
         new_unittest("flip and initial gaps (Fig. B.1)", test_gaps), &
         new_unittest("input/ decks are what mkdeck generates", test_input_decks) &
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
end module test_surfaces
