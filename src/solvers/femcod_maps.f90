!> Pressure and gap maps of the recorded load states, and their contact patches (no I/O).
module femcod_maps
   use femcod_kinds, only: dp
   use femcod_problem, only: contact_problem
   use femcod_scene, only: initial_gap_map
   use femcod_solver_options, only: cg_settings
   use femcod_elastic_operator, only: grid_operator, grid_operator_setup, grid_operator_free, TABLE_NONE
   use femcod_contact_result, only: load_state
   use femcod_patches, only: contact_patches, find_patches
   implicit none
   private
   public :: load_maps, state_maps, tangential_step_maps, state_pressure_map

   !> The gap map of one load state, and its contact patches (model/femcod_patches). Its
   !> pressure map is formed where it is written (state_pressure_map), from the state's
   !> contact list: 8 bytes a pixel a state less held.
   type :: state_maps
      real(dp), allocatable :: gap(:, :)
      !> The gap map is not here but in the result file being written (PREFIX.h5's
      !> temporary: femcod run's observer wrote it when the state was solved).
      logical :: gap_in_file = .false.
      type(contact_patches) :: patches
   end type state_maps

contains

   !> For every reached state: its contact patches (kept in the state's values too);
   !> gap(i, j) (nm) = separation of the deformed surfaces, g0 - approach + c (I * F),
   !> from the elastic operator's zero-padded FFT convolution (cyclic on a periodic cell),
   !> and 0 at the contacts (where the penalty springs' compression s F is the only
   !> remaining separation). The operator is made once for all states, and only when a
   !> state lacks the gap map its solver already had (the cg solver's, from the same
   !> formula and its own last double-precision convolution).
   subroutine load_maps(problem, states, maps, periodic, in_file)
      type(contact_problem), intent(in) :: problem
      !> A gap map a state holds (the cg solver's) is moved into `maps`, not copied.
      type(load_state), intent(inout) :: states(:)
      type(state_maps), allocatable, intent(out) :: maps(:)
      !> The grid is one cell of a periodic surface (default: free).
      logical, intent(in), optional :: periodic
      !> The states whose gap maps are in the result file already (state_maps'
      !> gap_in_file): not made again.
      logical, intent(in), optional :: in_file(:)
      logical :: cyclic
      type(grid_operator) :: op
      type(cg_settings) :: plain
      real(dp), allocatable :: force(:, :), disp(:, :)
      logical, allocatable :: handed(:)
      integer :: np, k, s
      allocate(maps(size(states)))
      if (.not. any(states%reached)) return
      np = problem%np
      cyclic = .false.
      if (present(periodic)) cyclic = periodic
      handed = allocated_gap(states)
      if (present(in_file)) then
         maps%gap_in_file = in_file .and. states%reached
         handed = handed .or. maps%gap_in_file
      end if
      do s = 1, size(states)
         if (.not. states(s)%reached) cycle
         call find_patches(np, states(s)%i, states(s)%j, cyclic, maps(s)%patches)
         states(s)%patches_4 = maps(s)%patches%count4
         states(s)%patches_8 = maps(s)%patches%count8
         if (allocated(states(s)%gap)) call move_alloc(states(s)%gap, maps(s)%gap)
      end do
      if (all(handed .or. .not. states%reached)) return
      allocate(force(np, np), disp(np, np))
      ! The elastic operator of the whole kernel in double precision, estimated plans, no
      ! preconditioner, no table kept: c (I * F), g0 and the springs' s of the deck.
      plain%single_until = 0
      plain%precondition = .false.
      call grid_operator_setup(op, initial_gap_map(problem%lower, problem%upper), problem, problem%pixel, plain, &
         cyclic, tables=TABLE_NONE)
      do s = 1, size(states)
         if (.not. states(s)%reached .or. handed(s)) cycle
         force = 0
         do k = 1, size(states(s)%force)
            force(states(s)%i(k), states(s)%j(k)) = states(s)%force(k)
         end do
         call op%displace(force, disp)
         maps(s)%gap = op%g0 - states(s)%approach + disp
         do k = 1, size(states(s)%force)
            ! A capped pixel (--plastic) keeps its negative gap, the springs' compression
            ! s F included: minus its plastic displacement.
            if (allocated(states(s)%plastic)) then
               if (states(s)%plastic(states(s)%i(k), states(s)%j(k)) > 0) then
                  maps(s)%gap(states(s)%i(k), states(s)%j(k)) = maps(s)%gap(states(s)%i(k), states(s)%j(k)) + &
                     op%s*states(s)%force(k)
                  cycle
               end if
            end if
            maps(s)%gap(states(s)%i(k), states(s)%j(k)) = 0
         end do
      end do
      call grid_operator_free(op)
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
