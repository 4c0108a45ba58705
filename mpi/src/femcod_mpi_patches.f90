!> The contact patches of a state on ranks (model/femcod_patches on one core): each rank
!> labels the patches of its slab of columns, and rank 0 joins the patches that meet
!> across the slabs' edges (and across the cell's edge on a periodic cell) by union-find
!> over the labels of every slab's first and last column. The counts, 4- and 8-connected,
!> are the serial ones; every rank gets them. No I/O.
module femcod_mpi_patches
   use mpi_f08, only: MPI_Comm, MPI_Gather, MPI_Bcast, MPI_INTEGER
   use femcod_patches, only: label_patches
   implicit none
   private
   public :: count_patches_on_ranks

contains

   !> The number of 4- and 8-connected patches of `contact` (this rank's columns of an
   !> NP-row grid; the ranks' slabs follow each other in rank order).
   subroutine count_patches_on_ranks(comm, ranks, rank, columns, contact, periodic, count4, count8)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: ranks, rank
      !> Every rank's number of columns, (0:ranks-1).
      integer, intent(in) :: columns(0:)
      logical, intent(in) :: contact(:, :)
      logical, intent(in) :: periodic
      integer, intent(out) :: count4, count8
      call count_one(.false., count4)
      call count_one(.true., count8)
   contains
      subroutine count_one(diagonal, total)
         logical, intent(in) :: diagonal
         integer, intent(out) :: total
         integer, allocatable :: labels(:, :), edges(:, :), all_edges(:, :, :), counts(:)
         integer :: n, local, result(1)
         n = size(contact, 1)
         allocate(labels(n, size(contact, 2)), edges(n, 2))
         call label_patches(contact, periodic, diagonal, labels, local, wrap_columns=.false.)
         edges = 0
         if (size(contact, 2) > 0) then
            edges(:, 1) = labels(:, 1)
            edges(:, 2) = labels(:, size(contact, 2))
         end if
         deallocate(labels)
         allocate(counts(0:ranks - 1), all_edges(n, 2, 0:ranks - 1))
         call MPI_Gather(local, 1, MPI_INTEGER, counts, 1, MPI_INTEGER, 0, comm)
         call MPI_Gather(edges, 2*n, MPI_INTEGER, all_edges, 2*n, MPI_INTEGER, 0, comm)
         if (rank == 0) result(1) = joined_count(counts, columns, all_edges, periodic, diagonal)
         call MPI_Bcast(result, 1, MPI_INTEGER, 0, comm)
         total = result(1)
      end subroutine count_one
   end subroutine count_patches_on_ranks

   !> Rank 0: the patches of all slabs, less the joins across their edges. Labels are made
   !> global by each slab's offset; a slab without columns is passed over.
   integer function joined_count(counts, columns, edges, periodic, diagonal) result(total)
      integer, intent(in) :: counts(0:), columns(0:), edges(:, :, 0:)
      logical, intent(in) :: periodic, diagonal
      integer, allocatable :: parent(:), offset(:), order(:)
      integer :: n, r, k, i, a, b, di, ii
      n = size(edges, 1)
      allocate(offset(0:size(counts) - 1))
      offset(0) = 0
      do r = 1, size(counts) - 1
         offset(r) = offset(r - 1) + counts(r - 1)
      end do
      total = sum(counts)
      allocate(parent(total))
      parent = [(k, k = 1, total)]
      ! The slabs that have columns, in order: a slab's last column meets the next one's first.
      order = pack([(r, r = 0, size(counts) - 1)], columns > 0)
      do k = 1, size(order)
         if (k == size(order) .and. .not. periodic) exit
         a = order(k)
         b = order(modulo(k, size(order)) + 1)
         do i = 1, n
            if (edges(i, 2, a) == 0) cycle
            do di = -1, 1
               if (di /= 0 .and. .not. diagonal) cycle
               ii = i + di
               if (periodic) ii = modulo(ii - 1, n) + 1
               if (ii < 1 .or. ii > n) cycle
               if (edges(ii, 1, b) == 0) cycle
               call join(edges(i, 2, a) + offset(a), edges(ii, 1, b) + offset(b))
            end do
         end do
      end do
   contains
      subroutine join(x, y)
         integer, intent(in) :: x, y
         integer :: rx, ry
         rx = root(x)
         ry = root(y)
         if (rx == ry) return
         parent(max(rx, ry)) = min(rx, ry)
         total = total - 1
      end subroutine join
      integer function root(x)
         integer, intent(in) :: x
         integer :: y, up
         root = x
         do while (parent(root) /= root)
            root = parent(root)
         end do
         y = x
         do while (parent(y) /= root)
            up = parent(y)
            parent(y) = root
            y = up
         end do
      end function root
   end function joined_count
end module femcod_mpi_patches
