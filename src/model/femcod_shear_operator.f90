!> The tangential (Cerruti) operator: the relative tangential displacements (nm) of the
!> two surfaces from the tangential forces (nN) on an NP x NP grid of pixels,
!> u_x = xx * t_x + xy * t_y, u_y = xy * t_x + yy * t_y (femcod_cerruti's tables; * the
!> convolution over the grid, zero-padded on the free surface, cyclic on the periodic
!> cell), what the tangential step (solvers/femcod_tangential) iterates with.
!>
!> As the elastic operator (femcod_elastic_operator) one process holds the columns
!> j0 + 1 .. j0 + nj: all of them on one core (grid_shear_operator, here), a slab on MPI
!> ranks (mpi/src/femcod_mpi_shear extends this type). Every sum and maximum the step
!> takes over the contacts goes through the operator's reductions, so the iteration is
!> written once for both.
!>
!> No I/O and no stop.
module femcod_shear_operator
   use femcod_kinds, only: dp
   use femcod_problem, only: contact_problem
   use femcod_cerruti, only: tangential_tables, periodic_tangential_spectra
   use femcod_convolution, only: shear_transform, shear_transform_setup, shear_transform_setup_periodic, &
      shear_transform_apply, shear_transform_free
   implicit none
   private
   public :: shear_operator, grid_shear_operator, grid_shear_setup, grid_shear_free

   !> What every tangential operator has and does (module header).
   type, abstract :: shear_operator
      !> Grid side; this part's first column (0-based) and number of columns.
      integer :: np = 0, j0 = 0, nj = 0
      !> The grid is one cell of a periodic surface (the kernel summed over the images).
      logical :: periodic = .false.
      !> The largest eigenvalue of the operator's 2 x 2 spectrum over the frequencies
      !> (nm/nN): a bound on its largest eigenvalue on any set of pixels.
      real(dp) :: largest = 0
   contains
      !> (ux, uy) = the operator applied to (tx, ty), this part's columns (np, nj).
      procedure(shear_displace_interface), deferred :: displace
      !> values(:), this part's sums or maxima, become the whole grid's.
      procedure :: sum_over_grid => local_reduction
      procedure :: max_over_grid => local_reduction
      !> The 2-norm of values(:, :) (this part's) over the whole grid.
      procedure :: norm_over_grid => local_norm
   end type shear_operator

   abstract interface
      subroutine shear_displace_interface(op, tx, ty, ux, uy)
         import :: shear_operator, dp
         class(shear_operator), intent(inout) :: op
         real(dp), intent(in) :: tx(:, :), ty(:, :)
         real(dp), intent(out) :: ux(:, :), uy(:, :)
      end subroutine shear_displace_interface
   end interface

   !> The whole grid in one process, by FFTW (femcod_convolution's shear_transform).
   type, extends(shear_operator) :: grid_shear_operator
      type(shear_transform) :: transform
   contains
      procedure :: displace => grid_displace
   end type grid_shear_operator

contains

   subroutine local_reduction(op, values)
      class(shear_operator), intent(inout) :: op
      real(dp), intent(inout) :: values(:)
   end subroutine local_reduction

   real(dp) function local_norm(op, values) result(norm)
      class(shear_operator), intent(inout) :: op
      real(dp), intent(in) :: values(:, :)
      norm = norm2(values)
   end function local_norm

   !> The operator of `problem`'s two bodies (their Young's moduli, GPa, and Poisson's
   !> ratios; the pixel, nm) on its grid: the free surface, or with `periodic` the cell.
   subroutine grid_shear_setup(op, problem, periodic)
      type(grid_shear_operator), intent(inout) :: op
      type(contact_problem), intent(in) :: problem
      logical, intent(in) :: periodic
      real(dp), allocatable :: xx(:, :), yy(:, :), xy(:, :)
      integer :: np
      call grid_shear_free(op)
      np = problem%np
      op%np = np
      op%j0 = 0
      op%nj = np
      op%periodic = periodic
      if (periodic) then
         allocate(xx(np/2 + 1, np), yy(np/2 + 1, np), xy(np/2 + 1, np))
         call periodic_tangential_spectra(np, problem%pixel, problem%young(1:2), problem%poisson(1:2), xx, yy, xy)
         call shear_transform_setup_periodic(op%transform, xx, yy, xy)
      else
         allocate(xx(0:np - 1, 0:np - 1), yy(0:np - 1, 0:np - 1), xy(0:np - 1, 0:np - 1))
         call tangential_tables(np, problem%pixel, problem%young(1:2), problem%poisson(1:2), xx, yy, xy)
         call shear_transform_setup(op%transform, xx, yy, xy)
      end if
      op%largest = op%transform%largest
   end subroutine grid_shear_setup

   subroutine grid_shear_free(op)
      type(grid_shear_operator), intent(inout) :: op
      call shear_transform_free(op%transform)
   end subroutine grid_shear_free

   subroutine grid_displace(op, tx, ty, ux, uy)
      class(grid_shear_operator), intent(inout) :: op
      real(dp), intent(in) :: tx(:, :), ty(:, :)
      real(dp), intent(out) :: ux(:, :), uy(:, :)
      call shear_transform_apply(op%transform, tx, ty, ux, uy)
   end subroutine grid_displace
end module femcod_shear_operator
