!> `femcod refine` without its I/O: the solve at the deck's resolution (and at 2d and 4d
!> for Richardson), the spectrum and its fit, and the area fraction against magnification
!> by the refinement (femcod_refine), Richardson's extrapolation and Persson's theory.
module femcod_refine_study
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE
   use femcod_strings, only: format_real
   use femcod_clock, only: wall_clock
   use femcod_problem, only: contact_problem
   use femcod_scene, only: initial_gap_map, rms_slope
   use femcod_surfaces, only: block_average
   use femcod_love, only: composite_modulus
   use femcod_maps, only: state_pressure_map
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, SOLVER_CG, BOUNDARY_PERIODIC
   use femcod_solver, only: solve_contact
   use femcod_refine, only: surface_spectrum, surface_spectrum_of, fit_spectrum, subpixel_slope_variance, &
      refined_fraction, persson_fraction, richardson_area, magnifications, calibrate_kappa, kappa_decay, kappa_drift, &
      band_kappa, band_edge
   implicit none
   private
   public :: refine_answer, refine_contact

   real(dp), parameter :: PI = acos(-1.0_dp)

   !> A pressure map (GPa), one per load.
   type :: pressure_set
      real(dp), allocatable :: p(:, :)
   end type pressure_set

   !> Everything `femcod refine` reports.
   type :: refine_answer
      type(surface_spectrum) :: spectrum
      !> E* (GPa) of the two bodies.
      real(dp) :: estar = 0
      !> The loads (nN) and the magnifications (1 = the pixel).
      real(dp), allocatable :: loads(:), zeta(:)
      !> Area fractions: the solve at d, 2d, 4d per load; by each method per magnification
      !> and load (zeta, load).
      real(dp), allocatable :: coarse(:, :)
      real(dp), allocatable :: refined(:, :), richardson(:, :), persson(:, :)
      !> The refinement with Persson's own constant sqrt(2) in place of the measured one
      !> (zeta, load), and the measured constant kappa per load: over one octave (the solve
      !> at 2d carried to the area at d; the same for every load: one fit over all).
      real(dp), allocatable :: theory(:, :), kappa(:)
      !> The constant over two octaves (4d to d) and over the octave 4d to 2d, its fall with
      !> the band's octaves (kappa_decay; 0: none measured) and its change an octave finer
      !> (kappa_drift; 1: none measured), and the constant of each magnification's band
      !> (band_kappa); kappa_two and kappa_coarse NaN when the grid has no 4d level.
      real(dp) :: kappa_two = 0, kappa_coarse = 0, decay = 0, drift = 1
      real(dp), allocatable :: band(:)
      !> The uncertainty band (band_edge): its constants per magnification and the refined
      !> area fractions they give (zeta, load); the refined answer lies between them.
      real(dp), allocatable :: band_low(:), band_high(:), refined_low(:, :), refined_high(:, :)
      !> The dimensionless area-load slope (A/A0) / (p/(E* h'_rms)) (doc/studies.md, "The
      !> area-load slope kappa"): of the solve at d with the image's h'_rms at the pixel
      !> (rms_slope: forward differences, as every run reports it), and of the refined
      !> area with the slope down to each magnification's length, h'_rms^2 + the
      !> spectrum's slope variance from q_d to zeta q_d (zeta, load).
      real(dp) :: rms_slope = 0
      real(dp), allocatable :: slope_solve(:), slope_refined(:, :)
      !> Wall seconds: the solve at d; the solves at 2d and 4d; the spectrum, fit and refinement.
      real(dp) :: solve_seconds = 0, richardson_seconds = 0, refine_seconds = 0
   end type refine_answer

contains

   !> Refine `problem` at options%loads down to the length `down_to` (nm, below the pixel).
   subroutine refine_contact(problem, options, down_to, answer, status)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      real(dp), intent(in) :: down_to
      type(refine_answer), intent(out) :: answer
      type(status_type), intent(inout) :: status
      type(pressure_set), allocatable :: at_d(:), at_2d(:), at_4d(:)
      real(dp), allocatable :: g0(:, :)
      real(dp) :: t0, t1, t2
      if (status%code /= 0) return
      if (options%solver /= SOLVER_CG .or. size(options%loads) == 0) then
         call set_error(status, STATUS_USAGE, "refine solves with the cg solver at given loads (--loads)")
         return
      end if
      if (.not. (down_to > 0 .and. down_to < problem%pixel)) then
         call set_error(status, STATUS_USAGE, "--down-to "//format_real(down_to)//" nm: the refinement goes below the "// &
            "pixel, "//format_real(problem%pixel)//" nm")
         return
      end if
      answer%estar = composite_modulus(problem%young(1:2), problem%poisson(1:2))
      answer%loads = options%loads
      answer%zeta = magnifications(problem%pixel/down_to)
      call wall_clock(t0)
      g0 = initial_gap_map(problem%lower, problem%upper)
      answer%rms_slope = rms_slope(g0, problem%pixel, options%boundary == BOUNDARY_PERIODIC)
      call surface_spectrum_of(g0, problem%pixel, answer%spectrum)
      deallocate(g0)
      call fit_spectrum(answer%spectrum, status)
      if (status%code /= 0) return
      call wall_clock(t1)
      allocate(answer%coarse(3, size(answer%loads)))
      answer%coarse = ieee_value(1.0_dp, ieee_quiet_nan)
      call solve_level(problem, options, 1, answer%coarse(1, :), at_d, status)
      call wall_clock(t2)
      answer%solve_seconds = t2 - t1
      answer%refine_seconds = t1 - t0
      if (status%code /= 0) return
      if (modulo(problem%np, 4) == 0 .and. problem%np >= 16) then
         call solve_level(problem, options, 2, answer%coarse(2, :), at_2d, status)
         if (status%code == 0) call solve_level(problem, options, 4, answer%coarse(3, :), at_4d, status)
         call wall_clock(t0)
         answer%richardson_seconds = t0 - t2
         if (status%code /= 0) return
      end if
      call wall_clock(t0)
      call refine_states(problem, answer, at_d, at_2d, at_4d)
      call wall_clock(t1)
      answer%refine_seconds = answer%refine_seconds + (t1 - t0)
   end subroutine refine_contact

   !> The refinement, Persson and Richardson at every load and magnification.
   subroutine refine_states(problem, answer, at_d, at_2d, at_4d)
      type(contact_problem), intent(in) :: problem
      type(refine_answer), intent(inout) :: answer
      type(pressure_set), intent(in) :: at_d(:)
      type(pressure_set), allocatable, intent(in) :: at_2d(:), at_4d(:)
      real(dp) :: q_d, m2, p0, side
      integer :: k, z, nz, nl
      nz = size(answer%zeta)
      nl = size(answer%loads)
      allocate(answer%refined(nz, nl), answer%theory(nz, nl), answer%persson(nz, nl), answer%richardson(nz, nl), &
         answer%kappa(nl), answer%slope_refined(nz, nl), answer%slope_solve(nl), answer%refined_low(nz, nl), &
         answer%refined_high(nz, nl))
      answer%refined = ieee_value(1.0_dp, ieee_quiet_nan)
      answer%refined_low = answer%refined
      answer%refined_high = answer%refined
      answer%slope_refined = answer%refined
      answer%slope_solve = ieee_value(1.0_dp, ieee_quiet_nan)
      answer%theory = answer%refined
      answer%persson = answer%refined
      answer%richardson = answer%refined
      answer%kappa = sqrt(2.0_dp)
      answer%kappa_two = ieee_value(1.0_dp, ieee_quiet_nan)
      answer%kappa_coarse = answer%kappa_two
      q_d = PI/problem%pixel
      side = problem%np*problem%pixel
      ! The refinement's constant, from the steps 2d -> d, 4d -> 2d and 4d -> d the image
      ! resolves.
      if (allocated(at_2d)) answer%kappa = calibrated(answer, at_2d, subpixel_slope_variance(answer%spectrum, &
         q_d/2, q_d), 1)
      if (allocated(at_4d)) then
         answer%kappa_two = calibrated(answer, at_4d, subpixel_slope_variance(answer%spectrum, q_d/4, q_d), 1)
         answer%kappa_coarse = calibrated(answer, at_4d, subpixel_slope_variance(answer%spectrum, q_d/4, q_d/2), 2)
         answer%decay = kappa_decay(answer%kappa(1), answer%kappa_two)
         answer%drift = kappa_drift(answer%kappa(1), answer%kappa_coarse)
      end if
      answer%band = band_kappa(answer%kappa(1), answer%decay, answer%drift, answer%zeta)
      answer%band_low = band_edge(answer%kappa(1), answer%band, allocated(at_4d), .false.)
      answer%band_high = band_edge(answer%kappa(1), answer%band, allocated(at_4d), .true.)
      do k = 1, nl
         if (.not. allocated(at_d(k)%p)) cycle
         p0 = answer%loads(k)/side**2
         if (p0 > 0) answer%slope_solve(k) = answer%coarse(1, k)*answer%estar*answer%rms_slope/p0
         do z = 1, nz
            m2 = subpixel_slope_variance(answer%spectrum, q_d, answer%zeta(z)*q_d)
            answer%refined(z, k) = refined_fraction(at_d(k)%p, answer%estar, m2, answer%band(z))
            answer%theory(z, k) = refined_fraction(at_d(k)%p, answer%estar, m2, sqrt(2.0_dp))
            answer%refined_low(z, k) = refined_fraction(at_d(k)%p, answer%estar, m2, answer%band_low(z))
            answer%refined_high(z, k) = refined_fraction(at_d(k)%p, answer%estar, m2, answer%band_high(z))
            if (p0 > 0) answer%slope_refined(z, k) = answer%refined(z, k)*answer%estar* &
               sqrt(answer%rms_slope**2 + m2)/p0
            answer%persson(z, k) = persson_fraction(p0, answer%estar, answer%spectrum%slope_variance + m2)
            answer%richardson(z, k) = richardson_area(answer%coarse(1, k), answer%coarse(2, k), answer%coarse(3, k), &
               problem%pixel, problem%pixel/answer%zeta(z))
         end do
      end do
   end subroutine refine_states

   !> kappa that carries the pressures `coarser` (of the solve at 2d or 4d) to the area
   !> fractions of level `level` (answer%coarse: 1 the solve at d, 2 at 2d) over the loads
   !> reached at both (m2 of the band between them); sqrt 2 (Persson's) when none is.
   function calibrated(answer, coarser, m2, level) result(kappa)
      type(refine_answer), intent(in) :: answer
      type(pressure_set), intent(in) :: coarser(:)
      real(dp), intent(in) :: m2
      integer, intent(in) :: level
      real(dp) :: kappa
      real(dp), allocatable :: p(:, :, :)
      logical :: both(size(coarser))
      integer :: k, m, n
      kappa = sqrt(2.0_dp)
      do k = 1, size(coarser)
         both(k) = allocated(coarser(k)%p) .and. answer%coarse(level, k) == answer%coarse(level, k)
      end do
      if (.not. any(both)) return
      n = size(coarser(findloc(both, .true., 1))%p, 1)
      allocate(p(n, n, count(both)))
      m = 0
      do k = 1, size(coarser)
         if (.not. both(k)) cycle
         m = m + 1
         p(:, :, m) = coarser(k)%p
      end do
      kappa = calibrate_kappa(p, answer%estar, m2, pack(answer%coarse(level, :), both))
   end function calibrated

   !> The solve with both surfaces averaged in blocks of `block` x `block` pixels (1: as
   !> given; the resolution study's averaging): each load's area fraction and, when
   !> `pressures` has room, its pressure map.
   subroutine solve_level(problem, options, block, fraction, pressures, status)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      integer, intent(in) :: block
      real(dp), intent(inout) :: fraction(:)
      type(pressure_set), allocatable, intent(inout) :: pressures(:)
      type(status_type), intent(inout) :: status
      type(contact_problem) :: level
      type(contact_result) :: res
      integer :: k
      level = problem
      if (block > 1) then
         level%np = problem%np/block
         level%pixel = problem%pixel*block
         level%maxcont = level%np**2
         level%lower = block_average(problem%lower, block)
         level%upper = block_average(problem%upper, block)
      end if
      call solve_contact(level, options, res, status)
      if (status%code /= 0) return
      if (.not. allocated(pressures)) allocate(pressures(size(fraction)))
      do k = 1, size(fraction)
         if (.not. res%states(k)%reached) cycle
         fraction(k) = real(res%states(k)%contacts, dp)/real(level%np, dp)**2
         if (size(pressures) > 0) pressures(k)%p = state_pressure_map(level%np, level%pixel, res%states(k))
      end do
   end subroutine solve_level

end module femcod_refine_study
