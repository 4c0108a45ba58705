!> Pressure and gap maps of the recorded load states, and their contact patches (no I/O).
module femcod_maps
   use femcod_kinds, only: dp
   use femcod_problem, only: contact_problem
   use femcod_scene, only: initial_gap_map
   use femcod_love, only: offset_table, surface_compliance
   use femcod_love_periodic, only: periodic_offset_table
   use femcod_spring, only: spring_stiffness
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_free
   use femcod_contact_result, only: load_state
   use femcod_patches, only: contact_patches, find_patches
   implicit none
   private
   public :: load_maps, state_maps, tangential_step_maps, state_pressure_map

   !> The maps of one load state, and its contact patches (model/femcod_patches).
   type :: state_maps
      real(dp), allocatable :: pressure(:, :), gap(:, :)
      type(contact_patches) :: patches
   end type state_maps

contains

   !> For every reached state: pressure(i, j) (GPa) = contact force / pixel area;
   !> gap(i, j) (nm) = separation of the deformed surfaces, g0 - approach + c (I * F),
   !> from one zero-padded FFT convolution (cyclic on a periodic cell), and 0 at the contacts (where the penalty
   !> springs' compression s F is the only remaining separation). The Love table and the
   !> FFT plans are made once for all states, and only when a state lacks the gap map its
   !> solver already had (the cg solver's, from the same formula and its own last
   !> double-precision convolution).
   subroutine load_maps(problem, states, maps, periodic)
      type(contact_problem), intent(in) :: problem
      !> A gap map a state holds (the cg solver's) is moved into `maps`, not copied.
      type(load_state), intent(inout) :: states(:)
      type(state_maps), allocatable, intent(out) :: maps(:)
      !> The grid is one cell of a periodic surface (default: free).
      logical, intent(in), optional :: periodic
      logical :: cyclic
      type(love_convolution) :: conv
      real(dp), allocatable :: force(:, :), disp(:, :), g0(:, :), table(:, :)
      real(dp) :: c, spring
      logical, allocatable :: handed(:)
      integer :: np, k, s
      allocate(maps(size(states)))
      if (.not. any(states%reached)) return
      np = problem%np
      cyclic = .false.
      if (present(periodic)) cyclic = periodic
      handed = allocated_gap(states)
      do s = 1, size(states)
         if (.not. states(s)%reached) cycle
         maps(s)%pressure = state_pressure_map(np, problem%pixel, states(s))
         call find_patches(np, states(s)%i, states(s)%j, cyclic, maps(s)%patches)
         if (handed(s)) call move_alloc(states(s)%gap, maps(s)%gap)
      end do
      if (all(handed .or. .not. states%reached)) return
      allocate(force(np, np), disp(np, np), table(0:np - 1, 0:np - 1))
      if (cyclic) then
         table(:, :) = periodic_offset_table(np)
      else
         table(:, :) = offset_table(np)
      end if
      c = surface_compliance(problem%young(1), problem%poisson(1), problem%pixel) + &
         surface_compliance(problem%young(2), problem%poisson(2), problem%pixel)
      spring = 3/spring_stiffness(problem%young(3), problem%poisson(3), problem%pixel, problem%pixel)
      ! g0 is numbered pixel by pixel along rows: p = (i - 1) np + j.
      g0 = initial_gap_map(problem%lower, problem%upper)
      call convolution_setup(conv, table, periodic=cyclic)
      do s = 1, size(states)
         if (.not. states(s)%reached .or. handed(s)) cycle
         force = 0
         do k = 1, size(states(s)%force)
            force(states(s)%i(k), states(s)%j(k)) = states(s)%force(k)
         end do
         call convolution_apply(conv, force, disp)
         maps(s)%gap = g0 - states(s)%approach + c*disp
         do k = 1, size(states(s)%force)
            ! A capped pixel (--plastic) keeps its negative gap, the springs' compression
            ! s F included: minus its plastic displacement.
            if (allocated(states(s)%plastic)) then
               if (states(s)%plastic(states(s)%i(k), states(s)%j(k)) > 0) then
                  maps(s)%gap(states(s)%i(k), states(s)%j(k)) = maps(s)%gap(states(s)%i(k), states(s)%j(k)) + &
                     spring*states(s)%force(k)
                  cycle
               end if
            end if
            maps(s)%gap(states(s)%i(k), states(s)%j(k)) = 0
         end do
      end do
      call convolution_free(conv)
   contains
      elemental logical function allocated_gap(state)
         type(load_state), intent(in) :: state
         allocated_gap = allocated(state%gap)
      end function allocated_gap
   end subroutine load_maps

   !> A state's pressure map (GPa): its contact forces over the pixel's area, 0 elsewhere.
   function state_pressure_map(np, pixel, state) result(pressure)
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel
      type(load_state), intent(in) :: state
      real(dp), allocatable :: pressure(:, :)
      integer :: m, j
      allocate(pressure(np, np))
      ! Zeroed on all threads: most of the time is the first touch of fresh pages.
      !$omp parallel do schedule(static)
      do j = 1, np
         pressure(:, j) = 0
      end do
      !$omp end parallel do
      do m = 1, size(state%force)
         pressure(state%i(m), state%j(m)) = state%force(m)/pixel**2
      end do
   end function state_pressure_map

   !> A state's tangential step as four NP x NP maps: the tangential traction along x and
   !> y (GPa), 1 where the contact sticks, 1 where it slips (all 0 off contact, and
   !> without a tangential step).
   pure function tangential_step_maps(np, pixel, s) result(map)
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel
      type(load_state), intent(in) :: s
      real(dp) :: map(np, np, 4)
      integer :: k
      map = 0
      if (.not. allocated(s%stick)) return
      do k = 1, size(s%stick)
         map(s%i(k), s%j(k), :) = [s%shear_x(k)/pixel**2, s%shear_y(k)/pixel**2, merge(1.0_dp, 0.0_dp, s%stick(k)), &
            merge(0.0_dp, 1.0_dp, s%stick(k))]
      end do
   end function tangential_step_maps
end module femcod_maps
