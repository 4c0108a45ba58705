!> The resolution study of section 4.5: the deck's surfaces down-sampled by odd/odd
!> subsampling or 2 x 2 averaging, the event-exact contact history at each level, and
!> the estimates of Figs. 4.17, 4.18 and 4.21 beside it (femcod_resolution). One call
!> per level, so that a program can report progress between levels; no I/O.
module femcod_resolution_study
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE
   use femcod_problem, only: contact_problem, validate_problem
   use femcod_surfaces, only: downsample_subsample, downsample_average
   use femcod_scene, only: initial_gaps, flip_upper
   use femcod_love, only: surface_compliance, love_influence, composite_modulus
   use femcod_spring, only: spring_stiffness
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options
   use femcod_memory, only: available_memory
   use femcod_observer, only: solver_observer
   use femcod_solver, only: solve_contact
   use femcod_richardson, only: power_law_fit
   use femcod_resolution, only: uncoupled_curve, mccool_parameters, mccool_surface, mccool_area, &
      richardson_area
   use femcod_strings, only: int_str
   implicit none
   private
   public :: resolution_level, level_deck, solve_level, extrapolate_levels, check_levels

   !> One resolution level: its deck, femcod's history and the estimates. Loads nN,
   !> lengths nm, areas nm^2.
   type :: resolution_level
      integer :: np = 0
      real(dp) :: pixel = 0
      !> The event-exact history at this level.
      type(contact_result) :: res
      !> Power law area = prefactor * load^exponent fitted over the history (steps with
      !> a positive load).
      real(dp) :: exponent = 0, prefactor = 0
      !> Single-pixel compliance (nm/nN) and the uncoupled model at the history's
      !> approaches.
      real(dp) :: compliance = 0
      real(dp), allocatable :: uncoupled_load(:), uncoupled_area(:)
      !> McCool's parameters and his area at the history's loads.
      type(mccool_parameters) :: mccool
      real(dp), allocatable :: mccool_area(:)
      !> Richardson extrapolation between the next coarser level and this one, at this
      !> level's loads within the coarser history (empty for the coarsest level).
      integer :: coarser_np = 0
      real(dp), allocatable :: richardson_load(:), richardson_area(:)
      !> The same level with the pressures capped at the hardness (the event path with
      !> --plastic; Fig. 4.21's capped curve), when asked for: `has_capped`.
      logical :: has_capped = .false.
      type(contact_result) :: capped
   end type resolution_level

contains

   !> The deck at `np` pixels per side: the surfaces halved by `method` ("subsample":
   !> odd/odd pixels; "average": 2 x 2 means) until they have `np` pixels, pixel size
   !> doubled each time, MAXCONT scaled by the pixel count (the same area fraction).
   subroutine level_deck(deck, np, method, level, status)
      type(contact_problem), intent(in) :: deck
      integer, intent(in) :: np
      character(len=*), intent(in) :: method
      type(contact_problem), intent(out) :: level
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: chain
      if (status%code /= 0) return
      if (method /= "subsample" .and. method /= "average") then
         call set_error(status, STATUS_USAGE, "--method expects subsample or average, found '"//method//"'")
         return
      end if
      level%label = deck%label
      level%np = deck%np
      level%pixel = deck%pixel
      level%young = deck%young
      level%poisson = deck%poisson
      level%lower = deck%lower
      level%upper = deck%upper
      chain = int_str(level%np)
      do while (level%np > np)
         if (method == "subsample") then
            level%lower = downsample_subsample(level%lower)
            level%upper = downsample_subsample(level%upper)
         else
            level%lower = downsample_average(level%lower)
            level%upper = downsample_average(level%upper)
         end if
         level%np = size(level%lower, 1)
         level%pixel = 2*level%pixel
         chain = chain//", "//int_str(level%np)
         if (level%np < 1) exit
      end do
      if (level%np /= np) then
         call set_error(status, STATUS_USAGE, "resolution level "//int_str(np)//" cannot be reached from NP = "// &
            int_str(deck%np)//" by halving ("//method//" gives "//chain//")")
         return
      end if
      level%maxcont = max(1, min(np*np, nint(deck%maxcont*(real(np, dp)/deck%np)**2)))
      call validate_problem(level, status)
   end subroutine level_deck

   !> Every level of a study checked before the first is solved: each reachable from NP by
   !> the method's halving (subsample: (n + 1)/2, average: n/2, as level_deck makes them),
   !> and none asked twice. STATUS_USAGE.
   subroutine check_levels(np, levels, method, status)
      integer, intent(in) :: np, levels(:)
      character(len=*), intent(in) :: method
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: chain
      integer :: k, n
      if (status%code /= 0) return
      do k = 1, size(levels)
         if (count(levels == levels(k)) > 1) then
            call set_error(status, STATUS_USAGE, "--levels: "//int_str(levels(k))//" is given twice")
            return
         end if
         n = np
         chain = int_str(n)
         do while (n > levels(k) .and. n > 1)
            n = merge((n + 1)/2, n/2, method == "subsample")
            chain = chain//", "//int_str(n)
         end do
         if (n /= levels(k)) then
            call set_error(status, STATUS_USAGE, "resolution level "//int_str(levels(k))//" cannot be reached "// &
               "from NP = "//int_str(np)//" by halving ("//method//" gives "//chain//"); nothing was solved")
            return
         end if
      end do
   end subroutine check_levels

   !> Solve one level and compute its estimates; with `capped` true solve it a second
   !> time with the pressures capped at the hardness (the plastic events of the event
   !> path), for the capped curve of Fig. 4.21.
   subroutine solve_level(deck, np, method, hardness, level, status, observer, capped, shear)
      type(contact_problem), intent(in) :: deck
      integer, intent(in) :: np
      character(len=*), intent(in) :: method
      real(dp), intent(in) :: hardness
      type(resolution_level), intent(out) :: level
      type(status_type), intent(inout) :: status
      !> Told of the solve's progress.
      class(solver_observer), intent(inout), optional :: observer
      logical, intent(in), optional :: capped
      !> The shear model's tau0 (GPa) and alpha (1), for the friction of every step
      !> (femcod_shear_model; capped at H/(3 sqrt 3) on the capped path).
      real(dp), intent(in), optional :: shear(2)
      type(contact_problem) :: d
      type(contact_options) :: options
      real(dp), allocatable :: load(:), area(:), composite(:, :)
      logical, allocatable :: keep(:)
      integer :: n
      call level_deck(deck, np, method, d, status)
      if (status%code /= 0) return
      level%np = d%np
      level%pixel = d%pixel
      options%hardness = hardness
      if (present(shear)) then
         options%shear = .true.
         options%shear_strength = shear(1)
         options%shear_slope = shear(2)
      end if
      allocate(options%loads(0))
      options%memory_available = available_memory()
      call solve_contact(d, options, level%res, status, observer)
      if (status%code /= 0) return
      if (present(capped)) level%has_capped = capped
      if (level%has_capped) then
         options%plastic = .true.
         call solve_contact(d, options, level%capped, status, observer)
         if (status%code /= 0) return
      end if
      n = level%res%nsteps
      load = level%res%step_load(1:n)
      area = level%res%step_contacts(1:n)*d%pixel**2
      keep = load > 0 .and. area > 0
      call power_law_fit(pack(load, keep), pack(area, keep), level%exponent, level%prefactor)
      ! The uncoupled model with the Boussinesq element's own single-pixel compliance
      ! (and the contact springs, as in the coupled model's diagonal).
      level%compliance = (surface_compliance(d%young(1), d%poisson(1), d%pixel) + &
         surface_compliance(d%young(2), d%poisson(2), d%pixel))*love_influence(0, 0) + &
         3/spring_stiffness(d%young(3), d%poisson(3), d%pixel, d%pixel)
      allocate(level%uncoupled_load(n), level%uncoupled_area(n))
      call uncoupled_curve(initial_gaps(d%lower, d%upper), level%compliance, d%pixel, level%res%step_approach(1:n), &
         level%uncoupled_load, level%uncoupled_area)
      ! McCool on the composite roughness (both surfaces as they face each other).
      composite = d%lower + flip_upper(d%upper)
      level%mccool = mccool_surface(composite, d%pixel)
      allocate(level%mccool_area(n))
      call mccool_area(level%mccool, composite_modulus(d%young(1:2), d%poisson(1:2)), (d%np*d%pixel)**2, &
         load/(d%np*d%pixel)**2, level%mccool_area)
   end subroutine solve_level

   !> Richardson extrapolation (rate 1, thesis Fig. 4.18b) of every level from the next
   !> coarser one in the set.
   pure subroutine extrapolate_levels(levels)
      type(resolution_level), intent(inout) :: levels(:)
      integer :: k, c, m, nf, nc
      real(dp), allocatable :: area(:), cload(:), carea(:), fload(:), farea(:)
      logical, allocatable :: keep(:)
      do k = 1, size(levels)
         ! The next coarser level: the largest NP below this one.
         c = 0
         do m = 1, size(levels)
            if (levels(m)%np < levels(k)%np) then
               if (c == 0) then
                  c = m
               else if (levels(m)%np > levels(c)%np) then
                  c = m
               end if
            end if
         end do
         allocate(levels(k)%richardson_load(0), levels(k)%richardson_area(0))
         if (c == 0) cycle
         levels(k)%coarser_np = levels(c)%np
         nc = levels(c)%res%nsteps
         nf = levels(k)%res%nsteps
         cload = levels(c)%res%step_load(1:nc)
         carea = levels(c)%res%step_contacts(1:nc)*levels(c)%pixel**2
         fload = levels(k)%res%step_load(1:nf)
         farea = levels(k)%res%step_contacts(1:nf)*levels(k)%pixel**2
         allocate(area(nf), keep(nf))
         call richardson_area(cload, carea, fload, farea, real(levels(k)%np, dp)/levels(c)%np, 1.0_dp, area, keep)
         levels(k)%richardson_load = pack(fload, keep)
         levels(k)%richardson_area = pack(area, keep)
         deallocate(area, keep)
      end do
   end subroutine extrapolate_levels
end module femcod_resolution_study
