!> A surface made on the ranks (`femcod-mpi --generate self-affine ...`): no input file,
!> no rank holding more than its own columns. The same surface as `femcod mkdeck
!> self-affine` with the same options on one core, to round-off:
!> - each rank draws its own columns of the spectrum (femcod_surfaces'
!>   self_affine_spectrum, the random stream jumped ahead to its first column);
!> - FFTW-MPI's complex 2-D backward transform of the distributed spectrum (the serial
!>   generator's transform: a Fortran (np, np) array is FFTW's row-major array with the
!>   columns first, which FFTW-MPI distributes), in the solver's column slabs;
!> - the real part, its mean removed and scaled to the rms height, the lowest point at
!>   0 nm, on the surface the spec names; the composite gaps as femcod_scene's
!>   initial_gap_map forms them, with the maxima and sums all-reduced.
!>
!> No I/O and no stop: errors come back in a status, the same on every rank.
module femcod_mpi_generate
   use mpi_f08
   use femcod_mpi_slab_transform, only: slab_dft, slab_dft_setup, slab_dft_backward, slab_dft_free
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec, scene_header
   use femcod_surfaces, only: self_affine_spectrum
   use femcod_solver_options, only: cg_settings
   use femcod_mpi_cg, only: column_split, coarse_factor, problem_constants
   use femcod_strings, only: int_str
   implicit none
   private
   public :: generate_columns, GENERATED_KINDS

   !> The kinds of `femcod mkdeck` that femcod-mpi makes on its ranks.
   character(len=*), parameter :: GENERATED_KINDS(1) = [character(len=11) :: "self-affine"]

contains

   !> The scene `spec` made on the ranks of `comm`: this rank's columns of the composite
   !> gaps in `local` (np x its count of column_split with the coarse start's width
   !> `block`), `constants` = [NP, pixel (nm), c, s (nm/nN)] as scatter_problem gives
   !> them, and on every rank the problem's header (no heights). Collective.
   subroutine generate_columns(spec, comm, how, problem, local, constants, block, status)
      type(scene_spec), intent(in) :: spec
      type(MPI_Comm), intent(in) :: comm
      type(cg_settings), intent(in) :: how
      type(contact_problem), intent(out) :: problem
      real(dp), allocatable, intent(out) :: local(:, :)
      real(dp), intent(out) :: constants(4)
      integer, intent(out) :: block
      type(status_type), intent(inout) :: status
      integer, allocatable :: first(:), count(:)
      real(dp), allocatable :: z(:, :)
      integer :: rank, ranks, np
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      constants = 0
      block = 1
      np = spec%np
      if (.not. any(GENERATED_KINDS == spec%kind)) then
         call set_error(status, STATUS_USAGE, "--generate "//spec%kind//": the ranks make "// &
            trim(GENERATED_KINDS(1))//" surfaces; write other kinds with femcod mkdeck and give the deck")
      else if (spec%plane) then
         call set_error(status, STATUS_USAGE, "--remove-plane with --generate: a generated surface has no tilt")
      else if (np < 2*ranks .or. .not. spec%pixel > 0) then
         call set_error(status, STATUS_USAGE, "--generate needs --np of at least two columns per rank ("// &
            int_str(2*ranks)//") and --pixel D > 0")
      end if
      if (status%code /= 0) return
      call scene_header(spec, np, 0, problem, status)
      if (status%code /= 0) return
      block = coarse_factor(np, ranks, how)
      call column_split(np, ranks, block, first, count)
      call self_affine_columns(spec, comm, first, count, z, status)
      if (status%code /= 0) return
      call gaps_of_shape(spec, comm, z, local)
      constants = problem_constants(problem)
   end subroutine generate_columns

   !> This rank's columns of the self-affine surface (femcod_surfaces' self_affine_surface
   !> on the ranks): the spectrum's columns, FFTW-MPI's backward transform, the real part
   !> with the mean removed and scaled to spec%rms, the lowest point at 0.
   subroutine self_affine_columns(spec, comm, first, count, z, status)
      type(scene_spec), intent(in) :: spec
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: first(0:), count(0:)
      real(dp), allocatable, intent(out) :: z(:, :)
      type(status_type), intent(inout) :: status
      type(slab_dft) :: dft
      real(dp) :: sums(2), lowest(1), n2, mean, rms
      integer :: rank, np, nj
      call MPI_Comm_rank(comm, rank)
      np = spec%np
      nj = count(rank)
      call slab_dft_setup(dft, comm, np, first(rank), nj, count(0), status)
      if (status%code == 0) then
         call self_affine_spectrum(np, spec%pixel, spec%hurst, spec%seed, first(rank), nj, dft%input)
         call slab_dft_backward(dft)
         z = real(dft%output, dp)
      end if
      call slab_dft_free(dft)
      if (status%code /= 0) return
      ! As self_affine_surface: z - mean, then scaled by rms / rms_height(z), whose mean
      ! is taken again (round-off).
      n2 = real(np, dp)**2
      sums(1) = sum(z)
      call MPI_Allreduce(MPI_IN_PLACE, sums(1:1), 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      z = z - sums(1)/n2
      sums(1) = sum(z)
      call MPI_Allreduce(MPI_IN_PLACE, sums(1:1), 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      mean = sums(1)/n2
      sums(2) = sum((z - mean)**2)
      call MPI_Allreduce(MPI_IN_PLACE, sums(2:2), 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      rms = sqrt(sums(2)/n2)
      if (rms > 0) z = z*(spec%rms/rms)
      ! A rough surface's lowest point at 0 nm (build_problem).
      lowest(1) = minval(z)
      call MPI_Allreduce(MPI_IN_PLACE, lowest, 1, MPI_DOUBLE_PRECISION, MPI_MIN, comm)
      z = z - lowest(1)
   end subroutine self_affine_columns

   !> The composite gaps of the shape z (this rank's columns) on the surface spec%shape_on
   !> names, the other flat: femcod_scene's initial_gap_map, (lower - max lower) + (upper
   !> flipped in its rows - max upper), then the largest of them less each, the maxima
   !> over all ranks. The rows' flip stays within a column.
   subroutine gaps_of_shape(spec, comm, z, g0)
      type(scene_spec), intent(in) :: spec
      type(MPI_Comm), intent(in) :: comm
      real(dp), intent(in) :: z(:, :)
      real(dp), allocatable, intent(out) :: g0(:, :)
      real(dp) :: tops(1)
      integer :: i, j, np
      np = size(z, 1)
      tops(1) = maxval(z)
      call MPI_Allreduce(MPI_IN_PLACE, tops, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      allocate(g0(np, size(z, 2)))
      if (spec%shape_on == "upper") then
         do j = 1, size(z, 2)
            do i = 1, np
               g0(i, j) = (0 - 0.0_dp) + (z(np + 1 - i, j) - tops(1))
            end do
         end do
      else
         do j = 1, size(z, 2)
            do i = 1, np
               g0(i, j) = (z(i, j) - tops(1)) + (0 - 0.0_dp)
            end do
         end do
      end if
      tops(1) = maxval(g0)
      call MPI_Allreduce(MPI_IN_PLACE, tops, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      g0 = tops(1) - g0
   end subroutine gaps_of_shape
end module femcod_mpi_generate
