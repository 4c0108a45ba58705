!> The tangential (Cerruti) operator on MPI ranks, and femcod-mpi's tangential step: the
!> shear operator of model/femcod_shear_operator on this rank's column slab, so that
!> solvers/femcod_tangential's one iteration (FISTA over the contacts' discs) runs on the
!> ranks unchanged.
!>
!> - The three spectra xx, yy, xy (femcod_cerruti) on this rank's frequencies: on the free
!>   surface from the tables' columns this rank holds, placed at the offsets
!>   -(NP-1) .. NP-1 (xx, yy even in both offsets, xy odd) and transformed by the slab
!>   transform (femcod_mpi_slab_transform), all three real; on the periodic cell from the
!>   alias sums in closed form, this rank's frequencies only.
!> - One application: the two force fields forward, the 2 x 2 multiplication, the two
!>   displacement fields back (four distributed transforms, as on one process).
!> - Sums, maxima and the 2-norm by MPI_Allreduce.
!>
!> No I/O and no stop: errors come back in a status, identical on every rank.
module femcod_mpi_shear
   use mpi_f08
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_cerruti, only: tangential_table_column, periodic_tangential_spectra_rows
   use femcod_shear_operator, only: shear_operator
   use femcod_tangential, only: tangential_request, tangential_answer, solve_tangential_on, keep_tangential_answer
   use femcod_observer, only: solver_observer
   use femcod_strings, only: int_str, sig_str
   use femcod_mpi_slab_transform, only: slab_transform, slab_setup, slab_free, slab_forward, slab_forward_field, &
      slab_backward, EXTEND_EVEN, EXTEND_ODD
   use femcod_mpi_cg, only: distributed_grid, distributed_state
   implicit none
   private
   public :: distributed_shear, distributed_shear_setup, distributed_shear_free, tangential_on_ranks, take_contact_list

   !> One rank's part of the tangential operator (the parent type: the grid side, this
   !> rank's columns, the periodic cell, the largest eigenvalue of the whole spectrum).
   type, extends(shear_operator) :: distributed_shear
      type(MPI_Comm) :: comm
      type(slab_transform) :: slab
      !> The spectra on this rank's frequencies (m, freqs), divided by m^2.
      real(dp), allocatable :: xx(:, :), yy(:, :), xy(:, :)
      !> The x component's spectrum during an application.
      complex(dp), allocatable :: along_x(:, :)
   contains
      procedure :: displace => distributed_shear_displace
      procedure :: sum_over_grid => sum_over_ranks
      procedure :: max_over_grid => max_over_ranks
      procedure :: norm_over_grid => norm_over_ranks
   end type distributed_shear

contains

   !> The operator on `grid`'s ranks and columns, free surface or periodic cell as the
   !> grid is, of the two bodies of `problem` (read on rank 0 only: its Young's moduli,
   !> GPa, and Poisson's ratios, sent to every rank; the pixel is the grid's). Collective.
   subroutine distributed_shear_setup(op, grid, problem, status)
      type(distributed_shear), intent(inout) :: op
      type(distributed_grid), intent(in) :: grid
      type(contact_problem), intent(in) :: problem
      type(status_type), intent(inout) :: status
      real(dp) :: materials(4), largest(1)
      real(dp), allocatable :: sxx(:, :), syy(:, :), sxy(:, :)
      call distributed_shear_free(op)
      if (grid%rank == 0) materials = [problem%young(1:2), problem%poisson(1:2)]
      call MPI_Bcast(materials, 4, MPI_DOUBLE_PRECISION, 0, grid%comm)
      op%comm = grid%comm
      op%np = grid%np
      op%j0 = grid%j0
      op%nj = grid%nj
      op%periodic = grid%periodic
      call slab_setup(op%slab, grid%comm, grid%np, grid%j0, grid%nj, grid%count(0), grid%periodic, .false., .false., &
         status)
      if (status%code /= 0) return
      associate(m => op%slab%m, freqs => op%slab%freqs)
         allocate(sxx(m, freqs), syy(m, freqs), sxy(m, freqs), op%along_x(m, freqs))
         if (grid%periodic) then
            call periodic_spectra(op, grid%pixel, materials, sxx, syy, sxy)
         else
            call free_spectra(op, grid%pixel, materials, sxx, syy, sxy)
         end if
         largest = -huge(1.0_dp)
         if (freqs > 0) largest = maxval((sxx + syy)/2 + sqrt(((sxx - syy)/2)**2 + sxy**2))
         call MPI_Allreduce(MPI_IN_PLACE, largest, 1, MPI_DOUBLE_PRECISION, MPI_MAX, op%comm)
         op%largest = largest(1)
         op%xx = sxx/real(m, dp)**2
         op%yy = syy/real(m, dp)**2
         op%xy = sxy/real(m, dp)**2
      end associate
   end subroutine distributed_shear_setup

   !> The free surface's spectra (nm/nN, not normalised) on this rank's frequencies: each
   !> table's columns of this rank, extended down the columns and along the rows by the
   !> table's parity, through the slab transform.
   subroutine free_spectra(op, pixel, materials, sxx, syy, sxy)
      type(distributed_shear), intent(inout) :: op
      real(dp), intent(in) :: pixel, materials(4)
      real(dp), intent(out) :: sxx(:, :), syy(:, :), sxy(:, :)
      real(dp), allocatable :: xx(:, :), yy(:, :), xy(:, :)
      integer :: jj
      allocate(xx(0:op%np - 1, op%nj), yy(0:op%np - 1, op%nj), xy(0:op%np - 1, op%nj))
      do jj = 1, op%nj
         call tangential_table_column(op%np, op%j0 + jj - 1, pixel, materials(1:2), materials(3:4), xx(:, jj), &
            yy(:, jj), xy(:, jj))
      end do
      call transform_table(xx, EXTEND_EVEN, sxx)
      call transform_table(yy, EXTEND_EVEN, syy)
      call transform_table(xy, EXTEND_ODD, sxy)
   contains
      !> The spectrum of a table placed at the offsets with the parity `how` in both.
      subroutine transform_table(table, how, spectrum)
         real(dp), intent(in) :: table(0:, :)
         integer, intent(in) :: how
         real(dp), intent(out) :: spectrum(:, :)
         integer :: i, j, np, m
         np = op%np
         m = op%slab%m
         do j = 1, op%nj
            op%slab%column_real(1:np, j) = table(:, j)
            op%slab%column_real(np + 1, j) = 0
            do i = np + 2, m
               op%slab%column_real(i, j) = how*table(m - i + 1, j)
            end do
         end do
         call slab_forward(op%slab, how)
         if (op%slab%freqs > 0) spectrum = real(op%slab%rows(:, 1:op%slab%freqs), dp)
      end subroutine transform_table
   end subroutine free_spectra

   !> The periodic cell's spectra (nm/nN, not normalised) on this rank's frequencies
   !> (femcod_cerruti's rows), transposed into the slab's layout (the columns' frequency
   !> first).
   subroutine periodic_spectra(op, pixel, materials, sxx, syy, sxy)
      type(distributed_shear), intent(inout) :: op
      real(dp), intent(in) :: pixel, materials(4)
      real(dp), intent(out) :: sxx(:, :), syy(:, :), sxy(:, :)
      real(dp), allocatable :: xx(:, :), yy(:, :), xy(:, :)
      integer :: freqs
      freqs = op%slab%freqs
      if (freqs <= 0) return
      allocate(xx(freqs, op%np), yy(freqs, op%np), xy(freqs, op%np))
      call periodic_tangential_spectra_rows(op%np, op%slab%freq_start, freqs, pixel, materials(1:2), materials(3:4), &
         xx, yy, xy)
      sxx = transpose(xx)
      syy = transpose(yy)
      sxy = transpose(xy)
   end subroutine periodic_spectra

   subroutine distributed_shear_free(op)
      type(distributed_shear), intent(inout) :: op
      call slab_free(op%slab)
      if (allocated(op%xx)) deallocate(op%xx, op%yy, op%xy, op%along_x)
   end subroutine distributed_shear_free

   !> (ux, uy) = the operator applied to (tx, ty), this rank's columns (np, nj): both
   !> forward, the 2 x 2 spectra, both back. Collective.
   subroutine distributed_shear_displace(op, tx, ty, ux, uy)
      class(distributed_shear), intent(inout) :: op
      real(dp), intent(in) :: tx(:, :), ty(:, :)
      real(dp), intent(out) :: ux(:, :), uy(:, :)
      complex(dp) :: sx, sy
      integer :: i, k
      call slab_forward_field(op%slab, tx)
      !$omp parallel do private(i)
      do k = 1, op%slab%freqs
         do i = 1, op%slab%m
            op%along_x(i, k) = op%slab%rows(i, k)
         end do
      end do
      call slab_forward_field(op%slab, ty)
      ! The y component's spectrum in the slab's rows, the x component's in along_x.
      !$omp parallel do private(i, sx, sy)
      do k = 1, op%slab%freqs
         do i = 1, op%slab%m
            sx = op%along_x(i, k)
            sy = op%slab%rows(i, k)
            op%along_x(i, k) = op%xx(i, k)*sx + op%xy(i, k)*sy
            op%slab%rows(i, k) = op%xy(i, k)*sx + op%yy(i, k)*sy
         end do
      end do
      call slab_backward(op%slab, uy)
      !$omp parallel do private(i)
      do k = 1, op%slab%freqs
         do i = 1, op%slab%m
            op%slab%rows(i, k) = op%along_x(i, k)
         end do
      end do
      call slab_backward(op%slab, ux)
   end subroutine distributed_shear_displace

   subroutine sum_over_ranks(op, values)
      class(distributed_shear), intent(inout) :: op
      real(dp), intent(inout) :: values(:)
      call MPI_Allreduce(MPI_IN_PLACE, values, size(values), MPI_DOUBLE_PRECISION, MPI_SUM, op%comm)
   end subroutine sum_over_ranks

   subroutine max_over_ranks(op, values)
      class(distributed_shear), intent(inout) :: op
      real(dp), intent(inout) :: values(:)
      call MPI_Allreduce(MPI_IN_PLACE, values, size(values), MPI_DOUBLE_PRECISION, MPI_MAX, op%comm)
   end subroutine max_over_ranks

   real(dp) function norm_over_ranks(op, values) result(norm)
      class(distributed_shear), intent(inout) :: op
      real(dp), intent(in) :: values(:, :)
      real(dp) :: total(1)
      total = sum(values**2)
      call MPI_Allreduce(MPI_IN_PLACE, total, 1, MPI_DOUBLE_PRECISION, MPI_SUM, op%comm)
      norm = sqrt(total(1))
   end function norm_over_ranks

   !> femcod run's tangential step (--tangential or --slip) at each state with contacts,
   !> on the ranks: this rank's contact pixels (take_contact_list, unless the state has
   !> them already) and their answer into the state. `problem` is read on rank 0 only.
   !> Collective.
   subroutine tangential_on_ranks(grid, problem, request, states, status, observer)
      type(distributed_grid), intent(inout) :: grid
      type(contact_problem), intent(in) :: problem
      type(tangential_request), intent(in) :: request
      type(distributed_state), intent(inout) :: states(:)
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      type(distributed_shear) :: op
      type(tangential_answer) :: answer
      real(dp) :: sticking(1)
      integer :: k
      if (status%code /= 0) return
      if (.not. any(states%contacts > 0)) return
      call distributed_shear_setup(op, grid, problem, status)
      do k = 1, size(states)
         if (status%code /= 0) exit
         associate(s => states(k))
            if (s%contacts == 0) cycle
            if (.not. allocated(s%tangential_i)) call take_contact_list(s%force, s%tangential_i, s%tangential_j, &
               s%contact_force)
            call solve_tangential_on(op, s%tangential_i, s%tangential_j, s%contact_force, request, answer, status, &
               observer)
            if (status%code /= 0) then
               status%message = "state "//int_str(k)//" (load "//sig_str(s%load, 6)//" nN): "//status%message
               exit
            end if
            call keep_tangential_answer(answer, s%state_values)
            sticking = s%stick_contacts
            call op%sum_over_grid(sticking)
            s%stick_contacts = nint(sticking(1))
         end associate
      end do
      call distributed_shear_free(op)
   end subroutine tangential_on_ranks

   !> This rank's contact pixels (forces > 0, nN; rows and columns 1 .. nj in column
   !> order) and their forces, from its force columns: all the tangential step needs of a
   !> state (distributed_state's tangential_i, tangential_j, contact_force), so that the
   !> columns may leave memory before it runs.
   pure subroutine take_contact_list(forces, rows, columns, contact_forces)
      real(dp), intent(in) :: forces(:, :)
      integer, allocatable, intent(out) :: rows(:), columns(:)
      real(dp), allocatable, intent(out) :: contact_forces(:)
      integer :: i, j, n
      n = count(forces > 0)
      allocate(rows(n), columns(n), contact_forces(n))
      n = 0
      do j = 1, size(forces, 2)
         do i = 1, size(forces, 1)
            if (forces(i, j) > 0) then
               n = n + 1
               rows(n) = i
               columns(n) = j
               contact_forces(n) = forces(i, j)
            end if
         end do
      end do
   end subroutine take_contact_list
end module femcod_mpi_shear
