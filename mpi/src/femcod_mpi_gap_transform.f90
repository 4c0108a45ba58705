!> The gap-variable iteration's transform grid (solvers/femcod_gap_cg) on MPI ranks: the
!> compliance C = c (I * .) + s and the stiffness K = C^-1, diagonal in Fourier space, on
!> the whole M x M transform grid (M = 2 NP zero-padded on the free surface, NP on the
!> periodic cell), whose every point is an unknown of the iteration.
!>
!> Layout: each rank holds the transform grid's columns that belong with its own grid
!> columns: its nj pixel columns j0 + 1 .. j0 + nj, and on the free surface besides the
!> nj padding columns NP + j0 + 1 .. NP + j0 + nj. Its field is (M, 2 nj) (free) or
!> (NP, nj) (periodic), pixel columns first, so that its pixels are the field's first
!> NP rows of its first nj columns, as the elastic operator says. The slab transpose
!> moves contiguous blocks of columns; in this order rank r's columns are the block
!> 2 r b .. 2 r b + 2 nj - 1 (b the solver's columns per rank), so the transposes move
!> the columns in that permuted order, and each rank puts its rows back in the natural
!> order (a local copy) before the transforms along them.
!>
!> Steps (femcod_mpi_slab_transform, on an M x M grid that is not extended, in the
!> permuted column order): r2c of length M down this rank's columns, transpose to this
!> rank's frequencies, c2c along the rows (natural order), the spectrum, back the same way.
!> The spectra are made from the distributed operator's kernel spectrum (the Love
!> table's, or the periodic cell's in closed form), on the same frequencies.
!>
!> No I/O and no stop.
module femcod_mpi_gap_transform
   use mpi_f08
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_NUMERICAL
   use femcod_elastic_operator, only: SPECTRUM_COMPLIANCE
   use femcod_strings, only: int_str
   use femcod_mpi_slab_transform, only: slab_transform, slab_setup, slab_free, slab_forward_field, slab_backward, &
      slab_permute
   implicit none
   private
   public :: distributed_gap_transform, gap_transform_setup, gap_transform_apply, gap_transform_free

   !> One rank's part of the transform grid (module header).
   type :: distributed_gap_transform
      !> The transform length M, the grid side np, this rank's field columns (2 nj or nj).
      integer :: m = 0, np = 0, columns = 0
      type(slab_transform) :: slab
      !> The spectra on this rank's frequencies (m, freqs), divided by m^2.
      real(dp), allocatable :: compliance(:, :), stiffness(:, :)
      !> The smallest value of C's spectrum on this rank (nm/nN; the zero frequency of a
      !> periodic cell left out).
      real(dp) :: smallest = huge(1.0_dp)
   end type distributed_gap_transform

contains

   !> The transform grid for a grid of side np split as the solver's columns (first(r),
   !> count(r) for each rank r; `block` columns per rank), with the kernel's spectrum
   !> `kernel` (m, freqs; divided by m^2) on frequencies freq_start.. of the same
   !> transposes, the compliance c and the springs' s (nm/nN). Collective.
   subroutine gap_transform_setup(t, comm, np, first, count, block, periodic, kernel, freq_start, c, s, status)
      type(distributed_gap_transform), intent(inout) :: t
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: np, first(0:), count(0:), block, freq_start
      logical, intent(in) :: periodic
      real(dp), intent(in) :: kernel(:, :), c, s
      type(status_type), intent(inout) :: status
      integer :: rank, pad
      call MPI_Comm_rank(comm, rank)
      pad = merge(1, 2, periodic)
      t%np = np
      t%m = pad*np
      t%columns = pad*count(rank)
      ! The field's M rows all count (no zero padding below them): a transform of an M x M
      ! grid, cyclic, over the ranks' columns in the permuted order.
      call slab_setup(t%slab, comm, t%m, pad*first(rank), t%columns, pad*block, .true., .false., .false., status)
      if (status%code /= 0) return
      if (t%slab%freq_start /= freq_start .or. t%slab%freqs /= size(kernel, 2) .or. size(kernel, 1) /= t%m) then
         call set_error(status, STATUS_NUMERICAL, "FFTW-MPI splits the transform grid's frequencies otherwise "// &
            "than the solver's: rank "//int_str(rank)//" has "//int_str(t%slab%freqs)//" from "// &
            int_str(t%slab%freq_start))
         return
      end if
      call slab_permute(t%slab, permutation(t, first, count, pad))
      call make_spectra(t, kernel, c, s, periodic)
   end subroutine gap_transform_setup

   !> natural(P) for the permuted order: rank r's positions 2 r b + 1 .. hold its pixel
   !> columns, then its padding columns (module header; the identity on a periodic cell).
   pure function permutation(t, first, count, pad) result(natural)
      type(distributed_gap_transform), intent(in) :: t
      integer, intent(in) :: first(0:), count(0:), pad
      integer :: natural(t%m)
      integer :: r, k, position
      position = 0
      do r = 0, size(count) - 1
         do k = 1, count(r)
            natural(position + k) = first(r) + k
         end do
         position = position + count(r)
         if (pad == 2) then
            do k = 1, count(r)
               natural(position + k) = t%np + first(r) + k
            end do
            position = position + count(r)
         end if
      end do
   end function permutation

   !> C = (c m^2 kernel + s)/m^2 and K = 1/(c m^2 kernel + s)/m^2 (kernel divided by m^2,
   !> as the serial femcod_convolution's gap_transform); on a periodic cell both 0 at zero
   !> frequency.
   pure subroutine make_spectra(t, kernel, c, s, periodic)
      type(distributed_gap_transform), intent(inout) :: t
      real(dp), intent(in) :: kernel(:, :), c, s
      logical, intent(in) :: periodic
      real(dp) :: m2
      logical :: zero
      integer :: i, k
      m2 = real(t%m, dp)**2
      allocate(t%compliance(t%m, t%slab%freqs), t%stiffness(t%m, t%slab%freqs))
      t%smallest = huge(1.0_dp)
      do k = 1, t%slab%freqs
         do i = 1, t%m
            zero = periodic .and. t%slab%freq_start + k == 1 .and. i == 1
            t%compliance(i, k) = c*(kernel(i, k)*m2) + s
            if (zero) then
               t%compliance(i, k) = 0
               t%stiffness(i, k) = 0
            else
               t%smallest = min(t%smallest, t%compliance(i, k))
               t%stiffness(i, k) = 1/t%compliance(i, k)/m2
               t%compliance(i, k) = t%compliance(i, k)/m2
            end if
         end do
      end do
   end subroutine make_spectra

   !> out = C in or K in (`which`) on this rank's field (m, columns). Collective.
   subroutine gap_transform_apply(t, which, in, out)
      type(distributed_gap_transform), intent(inout) :: t
      integer, intent(in) :: which
      real(dp), intent(in) :: in(:, :)
      real(dp), intent(out) :: out(:, :)
      integer :: k
      call slab_forward_field(t%slab, in)
      if (which == SPECTRUM_COMPLIANCE) then
         !$omp parallel do
         do k = 1, t%slab%freqs
            t%slab%rows(:, k) = t%slab%rows(:, k)*t%compliance(:, k)
         end do
      else
         !$omp parallel do
         do k = 1, t%slab%freqs
            t%slab%rows(:, k) = t%slab%rows(:, k)*t%stiffness(:, k)
         end do
      end if
      call slab_backward(t%slab, out)
   end subroutine gap_transform_apply

   subroutine gap_transform_free(t)
      type(distributed_gap_transform), intent(inout) :: t
      call slab_free(t%slab)
      t = distributed_gap_transform()
   end subroutine gap_transform_free
end module femcod_mpi_gap_transform
