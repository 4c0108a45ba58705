!> Pressure and gap maps of a recorded load state (no I/O).
module femcod_maps
   use femcod_kinds, only: dp
   use femcod_deck, only: deck_type
   use femcod_scene, only: initial_gaps
   use femcod_boussinesq, only: offset_table, surface_compliance
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_free
   use femcod_contact_result, only: load_state
   implicit none
   private
   public :: load_maps

contains

   !> pressure(i, j) (GPa) = contact force / pixel area; gap(i, j) (nm) = separation of
   !> the deformed surfaces, g0 - approach + c (I * F), from one zero-padded FFT
   !> convolution over the grid, and 0 at the contacts (where the penalty springs'
   !> compression s F is the only remaining separation).
   subroutine load_maps(deck, state, pressure, gap)
      type(deck_type), intent(in) :: deck
      type(load_state), intent(in) :: state
      real(dp), allocatable, intent(out) :: pressure(:, :), gap(:, :)
      type(love_convolution) :: conv
      real(dp), allocatable :: force(:, :), disp(:, :), g0(:), table(:, :)
      real(dp) :: c
      integer :: np, k
      np = deck%np
      allocate(pressure(np, np), gap(np, np), force(np, np), disp(np, np))
      force = 0
      do k = 1, size(state%force)
         force(state%i(k), state%j(k)) = state%force(k)
      end do
      pressure = force/deck%pixel**2
      allocate(table(0:np - 1, 0:np - 1))
      table = offset_table(np)
      c = surface_compliance(deck%young(1), deck%poisson(1), deck%pixel) + &
         surface_compliance(deck%young(2), deck%poisson(2), deck%pixel)
      call convolution_setup(conv, table)
      call convolution_apply(conv, force, disp)
      call convolution_free(conv)
      g0 = initial_gaps(deck%lower, deck%upper)
      ! g0 is stored pixel by pixel along rows: p = (i - 1) np + j.
      gap = transpose(reshape(g0, [np, np])) - state%approach + c*disp
      do k = 1, size(state%force)
         gap(state%i(k), state%j(k)) = 0
      end do
   end subroutine load_maps
end module femcod_maps
