!> The observer femcod-mpi gives its solver.
!>
!> - A stop signal (SIGTERM, SIGINT, SIGUSR1, caught by femcod_process) asks every rank
!>   to stop; the solver sums the requests, so that all ranks stop at the same iteration.
!> - Each state, as soon as it is solved: its columns go into the result file being built
!>   (femcod_mpi_results' write_state_columns), its two map figures are drawn on rank 0
!>   (their text kept until the result set is written), with --tangential its contact
!>   list is kept, and its columns leave memory (the forces are read from the solver's
!>   own columns: no copy). A run of many states thus holds the
!>   columns of one (16 bytes a pixel a state before, and on rank 0 16 MB a state of
!>   figure blocks).
module femcod_mpi_observer
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_strings, only: string_type, int_str, sig_str
   use femcod_svg, only: svg_pressure_map, svg_map, BLOCK_SMALLEST
   use femcod_process, only: stop_signal
   use femcod_mpi_cg, only: distributed_observer, distributed_grid, distributed_state
   use femcod_mpi_shear, only: take_contact_list
   use femcod_mpi_results, only: write_state_columns, gather_block_maxima
   implicit none
   private
   public :: signal_observer

   type, extends(distributed_observer) :: signal_observer
      !> The result file's temporary (begin_distributed_results made it); unallocated: the
      !> states keep their columns.
      character(len=:), allocatable :: path
      !> The figures' block width in pixels (figure_block).
      integer :: figure = 1
      !> Keep each state's contact list for the tangential step that follows the states.
      logical :: tangential = .false.
      !> Values of a rank's columns one collective write of a map takes (0: the writer's
      !> default; a test sets a few to write a small grid in several blocks).
      integer :: block_values = 0
      !> Each state's two figures (SVG text), by the state's place in the targets (rank 0).
      type(string_type), allocatable :: pressure_svg(:), gap_svg(:)
      !> The first failure to write a state's columns, the same on every rank: the solver
      !> is then asked to stop.
      type(status_type) :: written
   contains
      procedure :: stop_requested => signal_arrived
      procedure :: columns_solved => write_and_free
   end type signal_observer

contains

   logical function signal_arrived(self)
      class(signal_observer), intent(inout) :: self
      signal_arrived = stop_signal() /= 0 .or. self%written%code /= 0
   end function signal_arrived

   !> State k of n is solved: its columns into the file, its figures drawn on rank 0 as
   !> the serial writer draws them (the largest pressure of each block, at most 1024
   !> blocks a side; the smallest gap: no contact disappears), and out of memory.
   !> Collective. The pressure figure takes the blocks' largest force over the pixel's
   !> area (the same numbers as the largest pressure: division by a positive number keeps
   !> the order), the gap figure the blocks' largest negated gap, negated back: no copy of
   !> the columns is made.
   subroutine write_and_free(self, k, n, grid, state, forces)
      class(signal_observer), intent(inout) :: self
      integer, intent(in) :: k, n
      type(distributed_grid), intent(inout) :: grid
      type(distributed_state), intent(inout) :: state
      real(dp), intent(in) :: forces(:, :)
      real(dp), allocatable :: blocks(:, :)
      character(len=:), allocatable :: title
      if (.not. allocated(self%path) .or. self%written%code /= 0) return
      if (.not. allocated(self%pressure_svg)) allocate(self%pressure_svg(n), self%gap_svg(n))
      if (self%block_values > 0) then
         call write_state_columns(self%path, grid, k, n, state, forces, self%written, self%block_values)
      else
         call write_state_columns(self%path, grid, k, n, state, forces, self%written)
      end if
      if (self%written%code /= 0) return
      title = " at "//sig_str(state%load, 6)//" nN (approach "//sig_str(state%approach, 4)//" nm, "// &
         int_str(state%contacts)//" contacts"
      if (self%figure > 1) title = title//", "//int_str(self%figure)//" x "//int_str(self%figure)//" blocks"
      call gather_block_maxima(grid, forces, self%figure, blocks)
      if (grid%rank == 0) then
         blocks = blocks/grid%pixel**2
         self%pressure_svg(k)%s = svg_pressure_map("contact pressure"//title//")", blocks, grid%np*grid%pixel)
      end if
      deallocate(blocks)
      state%gap = -state%gap
      call gather_block_maxima(grid, state%gap, self%figure, blocks)
      if (grid%rank == 0) then
         blocks = -blocks
         self%gap_svg(k)%s = svg_map("gap"//title//")", blocks, grid%np*grid%pixel, "nm", "gap", BLOCK_SMALLEST, .false.)
      end if
      if (self%tangential) call take_contact_list(forces, state%tangential_i, state%tangential_j, state%contact_force)
      deallocate(state%gap)
      if (allocated(state%plastic)) deallocate(state%plastic)
   end subroutine write_and_free
end module femcod_mpi_observer
