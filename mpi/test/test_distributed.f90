!> The distributed fixed-load solver (femcod_mpi_cg) on the ranks it is run with. Every
!> test is collective: all ranks make the same calls, and a check's value is the same on
!> every rank (reduced before it is checked), so that no rank leaves a test early.
module test_distributed
   use mpi_f08
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, STATUS_USAGE
   use femcod_love, only: love_influence
   use femcod_problem, only: contact_problem
   use femcod_deck, only: read_deck
   use femcod_generate, only: scene_spec, build_problem
   use femcod_analytic, only: hertz_approach
   use femcod_solver_options, only: contact_options, cg_settings, run_shear_model, &
      SOLVER_CG, BOUNDARY_PERIODIC, LAW_HARD_WALL, LAW_DUGDALE, LAW_EXPONENTIAL
   use femcod_contact_result, only: contact_result
   use femcod_solver, only: solve_contact
   use femcod_interface_law, only: make_interface_law
   use femcod_mpi_generate, only: generate_columns
   use femcod_scene, only: initial_gap_map
   use femcod_mpi_cg, only: distributed_grid, distributed_state, distributed_observer, grid_setup, grid_free, &
      solve_loads, column_split, coarse_factor, distribute_problem, distributed_convolve
   use femcod_tangential, only: tangential_request_of
   use femcod_mpi_shear, only: tangential_on_ranks
   use femcod_mpi_observer, only: signal_observer
   use femcod_mpi_results, only: begin_distributed_results, gather_block_maxima
   use femcod_hdf5, only: h5_file, h5_open, h5_read, h5_close
   use femcod_results, only: load_group
   use femcod_files, only: remove_file
   implicit none
   private
   public :: collect_distributed

contains

   subroutine collect_distributed(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("column split and coarse width follow their definitions", test_split), &
         new_unittest("convolution = direct sum of Love's influence coefficients", test_convolution), &
         new_unittest("float32 convolution within float32's round-off of the double one", test_single), &
         new_unittest("direct corrections: the convolution of the changed forces, free and periodic", &
            test_direct_corrections), &
         new_unittest("the kernel split on the ranks: within its bound of the convolution", test_split_on_ranks), &
         new_unittest("too few columns for the ranks: refused on every rank", test_too_few_columns), &
         new_unittest("Hertz at 1000 nN on the 0.5 nm sphere deck", test_hertz), &
         new_unittest("--generate self-affine: mkdeck's surface on 1, 2 and 4 ranks, to round-off", test_generate), &
         new_unittest("the serial cg solver's answer on 1, 2 and 4 ranks, rough surface", test_against_serial), &
         new_unittest("the coarse start solved on the ranks: the serial answer at 256^2", test_coarse_on_ranks), &
         new_unittest("--plastic: the serial answer and plastic set on 1, 2 and 4 ranks", test_plastic_against_serial), &
         new_unittest("--approach: the serial loads on 1, 2 and 4 ranks", test_approach_against_serial), &
         new_unittest("--kernel-radius: the serial answer on 1, 2 and 4 ranks", test_truncated_against_serial), &
         new_unittest("--boundary periodic --plastic: the serial answer on 1, 2 and 4 ranks", &
         test_periodic_against_serial), &
         new_unittest("--adhesion exponential --approach: the serial path on 1, 2 and 4 ranks", &
            test_adhesion_against_serial), &
         new_unittest("--boundary periodic --adhesion dugdale --plastic --approach: the serial path on 1, 2, 4 ranks", &
            test_periodic_adhesion_against_serial), &
         new_unittest("--plastic --approach (the gap variables): the serial path on 1, 2 and 4 ranks", &
            test_plastic_approach_against_serial), &
         new_unittest("--boundary periodic --approach: the serial loads on 1, 2 and 4 ranks", &
         test_periodic_approach_against_serial), &
         new_unittest("--shear-strength --shear-slope --plastic: the serial friction on 1, 2 and 4 ranks", &
         test_friction_against_serial), &
         new_unittest("femcod-mpi's observer: each state's columns into the file as solved, then freed", &
            test_streamed_columns), &
         new_unittest("figure blocks gathered on rank 0: the whole map's block maxima (blocks across ranks)", &
            test_block_maxima), &
         new_unittest("--tangential (partial slip): the serial tractions and stick map on 1, 2 and 4 ranks", &
         test_tangential_against_serial), &
         new_unittest("--boundary periodic --slip: the serial tractions and stick map on 1, 2 and 4 ranks", &
         test_periodic_slip_against_serial) &
         ]
   end subroutine collect_distributed

   !> column_split (FFTW-MPI's block distribution): counts add up to NP, consecutive, each
   !> a multiple of the block, the first ones ceil(NP / (block ranks)) blocks, never
   !> growing from rank to rank; coarse_factor: the smallest power of two f >= 2 with
   !> f^2 >= ranks, 1 when NP is not a multiple of it or below 2 x the coarsest grid (64).
   subroutine test_split(error)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: first(:), count(:)
      type(cg_settings) :: how
      integer :: ranks, block, r
      do ranks = 1, 7
         do block = 1, 4
            call column_split(24*block, ranks, block, first, count)
            call check(error, sum(count) == 24*block .and. all(mod(count, block) == 0) .and. &
               count(0) == block*((24 + ranks - 1)/ranks) .and. first(0) == 0 .and. &
               all([(first(r) == first(r - 1) + count(r - 1) .and. count(r) <= count(r - 1), r = 1, ranks - 1)]), &
               "split of "//to_string(24*block)//" columns in blocks of "//to_string(block)//" over "// &
               to_string(ranks)//" ranks")
            if (allocated(error)) return
         end do
      end do
      call check(error, coarse_factor(256, 1, how), 2)
      if (allocated(error)) return
      call check(error, coarse_factor(256, 4, how), 2)
      if (allocated(error)) return
      call check(error, coarse_factor(256, 5, how), 4)
      if (allocated(error)) return
      call check(error, coarse_factor(256, 17, how), 8)
      if (allocated(error)) return
      call check(error, coarse_factor(100, 2, how), 1)
      if (allocated(error)) return
      call check(error, coarse_factor(130, 5, how), 1)
   end subroutine test_split

   !> The distributed padded convolution of a force field equals the direct sum
   !> u(i, j) = sum F(k, l) I(i - k, j - l) with Love's closed-form coefficients
   !> (femcod_love), NP = 12 (non-periodic: no image terms), to 1e-12 of max |u|, on up to
   !> 6 ranks (two columns each at least).
   subroutine test_convolution(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 12
      type(distributed_grid) :: grid
      type(status_type) :: status
      real(dp), allocatable :: f(:, :), mine(:, :), out(:, :)
      integer, allocatable :: first(:), count(:)
      integer :: ranks, rank, i, j, k, l
      real(dp) :: direct, worst(2)
      call MPI_Comm_size(MPI_COMM_WORLD, ranks)
      call MPI_Comm_rank(MPI_COMM_WORLD, rank)
      allocate(f(np, np))
      do j = 1, np
         do i = 1, np
            f(i, j) = sin(1.3_dp*i + 0.7_dp*j)**2 + 0.1_dp*i
         end do
      end do
      call column_split(np, ranks, 1, first, count)
      mine = f(:, first(rank) + 1:first(rank) + count(rank))
      allocate(out(np, count(rank)))
      if (minval(count) >= 2) then
         call grid_setup(grid, MPI_COMM_WORLD, np, 1, 0*mine, 1.0_dp, 1.0_dp, 0.0_dp, cg_settings(), status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         call distributed_convolve(grid, mine, out, 1.0_dp)
         worst = 0
         do j = 1, count(rank)
            do i = 1, np
               direct = 0
               do l = 1, np
                  do k = 1, np
                     direct = direct + f(k, l)*love_influence(i - k, first(rank) + j - l)
                  end do
               end do
               worst = max(worst, [abs(out(i, j) - direct), abs(direct)])
            end do
         end do
         call MPI_Allreduce(MPI_IN_PLACE, worst, 2, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
         call grid_free(grid)
         call check(error, worst(1) <= 1.0e-12_dp*worst(2), "largest difference "//to_string(worst(1))// &
            " of max |u| "//to_string(worst(2)))
      end if
   end subroutine test_convolution

   !> The float32 transforms (the search directions' convolution) against the double ones
   !> on a 64 x 64 field: the largest difference between 1e-9 (so that float32 was used)
   !> and 1e-5 of max |u| (float32's 6e-8 times the transforms' depth, 2 log2(128) = 14,
   !> with margin).
   subroutine test_single(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 64
      type(distributed_grid) :: grid
      type(status_type) :: status
      real(dp), allocatable :: mine(:, :), double(:, :), single(:, :)
      integer, allocatable :: first(:), count(:)
      integer :: ranks, rank, i, j
      real(dp) :: worst(2)
      call MPI_Comm_size(MPI_COMM_WORLD, ranks)
      call MPI_Comm_rank(MPI_COMM_WORLD, rank)
      call column_split(np, ranks, 1, first, count)
      allocate(mine(np, count(rank)), double(np, count(rank)), single(np, count(rank)))
      do j = 1, count(rank)
         do i = 1, np
            mine(i, j) = cos(0.37_dp*i*(first(rank) + j))**2
         end do
      end do
      call grid_setup(grid, MPI_COMM_WORLD, np, 1, 0*mine, 1.0_dp, 1.0_dp, 0.0_dp, cg_settings(), status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call distributed_convolve(grid, mine, double, 1.0_dp)
      call distributed_convolve(grid, mine, single, 1.0_dp, single=.true.)
      call grid_free(grid)
      worst = [maxval(abs(single - double)), maxval(abs(double))]
      call MPI_Allreduce(MPI_IN_PLACE, worst, 2, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
      call check(error, worst(1) > 1.0e-9_dp*worst(2) .and. worst(1) <= 1.0e-5_dp*worst(2), &
         "float32 - double: "//to_string(worst(1)/worst(2))//" of max |u|")
   end subroutine test_single

   !> The direct corrections on ranks (the shared float32 table, every rank's changes
   !> gathered): seven changed forces spread over the columns of a 64 x 64 grid, added to
   !> zero displacements, against the distributed convolution of the same forces (itself
   !> checked against Love's direct sum, test_convolution), within 1e-6 of max |u| (the
   !> table's float32 rounding, 6e-8 a term); and the shared table itself against the
   !> closed forms (femcod_love's coefficients, femcod_love_periodic's table) to float32's
   !> rounding. Free surface and periodic cell.
   subroutine test_direct_corrections(error)
      use femcod_love_periodic, only: periodic_offset_table
      use femcod_kinds, only: sp
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 64
      integer, parameter :: pixels(2, 7) = reshape([3, 1, 10, 5, 64, 20, 1, 33, 40, 40, 22, 63, 5, 64], [2, 7])
      real(dp), parameter :: deltas(7) = [1.5_dp, -0.25_dp, 2.0_dp, 0.75_dp, -1.0_dp, 0.5_dp, 3.0_dp]
      type(distributed_grid) :: grid
      type(cg_settings) :: how
      type(status_type) :: status
      real(dp), allocatable :: forces(:, :), direct(:, :), convolved(:, :), exact(:, :)
      integer, allocatable :: first(:), count(:), changed(:, :)
      real(dp), allocatable :: delta(:)
      integer :: ranks, rank, q, p, limit, split_limit, case
      real(dp) :: worst(4)
      logical :: periodic
      call MPI_Comm_size(MPI_COMM_WORLD, ranks)
      call MPI_Comm_rank(MPI_COMM_WORLD, rank)
      call column_split(np, ranks, 1, first, count)
      do case = 1, 2
         periodic = case == 2
         call grid_setup(grid, MPI_COMM_WORLD, np, 1, spread(spread(0.0_dp, 1, np), 2, count(rank)), 1.0_dp, &
            1.0_dp, 0.0_dp, how, status, periodic)
         call check(error, status%code, 0)
         if (allocated(error)) return
         call grid%correction_limits(how, limit, split_limit)
         allocate(forces(np, count(rank)), direct(np, count(rank)), convolved(np, count(rank)))
         forces = 0
         direct = 0
         changed = reshape([integer ::], [2, 0])
         delta = [real(dp) ::]
         ! This rank's changes, by column then row, in its own columns (1-based).
         do q = 1, size(deltas)
            if (pixels(2, q) > first(rank) .and. pixels(2, q) <= first(rank) + count(rank)) then
               changed = reshape([changed, pixels(1, q), pixels(2, q) - first(rank)], [2, size(changed, 2) + 1])
               delta = [delta, deltas(q)]
               forces(pixels(1, q), pixels(2, q) - first(rank)) = deltas(q)
            end if
         end do
         if (limit > 0) call grid%add_direct(direct, changed, delta, size(delta))
         call distributed_convolve(grid, forces, convolved, 1.0_dp)
         if (periodic) then
            exact = periodic_offset_table(np)
         else
            allocate(exact(0:np - 1, 0:np - 1))
            do p = 0, np - 1
               exact(:, p) = love_influence([(q, q = 0, np - 1)], p)
            end do
         end if
         worst = [maxval(abs(direct - convolved)), maxval(abs(convolved)), 0.0_dp, maxval(abs(exact))]
         if (limit > 0) worst(3) = maxval(abs(real(grid%table, dp) - exact))
         call MPI_Allreduce(MPI_IN_PLACE, worst, 4, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
         call grid_free(grid)
         deallocate(forces, direct, convolved, exact)
         call check(error, limit, how%direct_corrections, "direct corrections on one node")
         if (allocated(error)) return
         call check(error, worst(1) <= 1.0e-6_dp*worst(2), merge("periodic", "free    ", periodic)// &
            ": direct - convolved "//to_string(worst(1)/worst(2))//" of max |u|")
         if (allocated(error)) return
         call check(error, worst(3) <= real(epsilon(1.0_sp), dp)*worst(4), "shared table off the closed form by "// &
            to_string(worst(3)/worst(4))//" of its largest value")
         if (allocated(error)) return
      end do
   end subroutine test_direct_corrections

   !> The kernel split on the ranks (ranks_split_correct: every rank's changes applied to
   !> its own columns) against the distributed convolution of the same 48 changes on a
   !> 128^2 free surface: within the error bound the split returns (femcod_split_correction:
   !> c |delta| far_error(window) a change beyond its window) plus the float32 rounding
   !> of its near table. The bound is 7e-3 of max |u| here: a split that put the changes
   !> in the wrong columns would be off by the displacements themselves.
   subroutine test_split_on_ranks(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: np = 128, nchanges = 48
      type(distributed_grid) :: grid
      type(cg_settings) :: how
      type(status_type) :: status
      real(dp), allocatable :: forces(:, :), split(:, :), convolved(:, :), delta(:)
      integer, allocatable :: first(:), count(:), changed(:, :)
      integer :: ranks, rank, q, iq, jq, limit, split_limit
      real(dp) :: worst(2), bound
      logical :: applied
      call MPI_Comm_size(MPI_COMM_WORLD, ranks)
      call MPI_Comm_rank(MPI_COMM_WORLD, rank)
      call column_split(np, ranks, 1, first, count)
      call grid_setup(grid, MPI_COMM_WORLD, np, 1, spread(spread(0.0_dp, 1, np), 2, count(rank)), 1.0_dp, 1.0_dp, &
         0.0_dp, how, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call grid%correction_limits(how, limit, split_limit)
      call check(error, split_limit >= nchanges, "the split takes 48 changes")
      if (allocated(error)) return
      allocate(forces(np, count(rank)), split(np, count(rank)), convolved(np, count(rank)))
      forces = 0
      split = 0
      allocate(changed(2, 0), delta(0))
      ! 48 changes over the whole grid, by column (pixel (iq, jq), jq = 2 q + 1, iq = 1 +
      ! 37 q mod 128), each rank its own.
      do q = 1, nchanges
         jq = 2*q + 1
         iq = 1 + mod(37*q, np)
         if (jq > first(rank) .and. jq <= first(rank) + count(rank)) then
            changed = reshape([changed, iq, jq - first(rank)], [2, size(changed, 2) + 1])
            delta = [delta, real(mod(q, 5) - 2, dp) + 0.5_dp]
            forces(iq, jq - first(rank)) = delta(size(delta))
         end if
      end do
      bound = 0
      call grid%split_correct(split, changed, delta, size(delta), how, huge(1.0_dp), bound, applied)
      call distributed_convolve(grid, forces, convolved, 1.0_dp)
      worst = [maxval(abs(split - convolved)), maxval(abs(convolved))]
      call MPI_Allreduce(MPI_IN_PLACE, worst, 2, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
      call grid_free(grid)
      call check(error, applied, "the split applied")
      if (allocated(error)) return
      call check(error, worst(1) <= bound + 1.0e-6_dp*worst(2), "split - convolved "//to_string(worst(1))// &
         " beyond its bound "//to_string(bound))
   end subroutine test_split_on_ranks

   !> Each rank needs two columns (the preconditioner's halo): NP = 2 P - 1 is refused,
   !> with the usage code, on every rank.
   subroutine test_too_few_columns(error)
      type(error_type), allocatable, intent(out) :: error
      type(distributed_grid) :: grid
      type(status_type) :: status
      integer, allocatable :: first(:), count(:)
      integer :: ranks, rank, np, code
      call MPI_Comm_size(MPI_COMM_WORLD, ranks)
      call MPI_Comm_rank(MPI_COMM_WORLD, rank)
      np = 2*ranks - 1
      call column_split(np, ranks, 1, first, count)
      call grid_setup(grid, MPI_COMM_WORLD, np, 1, spread(spread(0.0_dp, 1, np), 2, count(rank)), 1.0_dp, 1.0_dp, &
         0.0_dp, cg_settings(), status)
      code = status%code
      call MPI_Allreduce(MPI_IN_PLACE, code, 1, MPI_INTEGER, MPI_MIN, MPI_COMM_WORLD)
      call check(error, code, STATUS_USAGE, "the smallest status code over the ranks")
   end subroutine test_too_few_columns

   !> A self-affine surface made on groups of 1, 2 and 4 ranks (generate_columns: each
   !> rank its columns of the spectrum, the random stream jumped ahead, FFTW-MPI's
   !> transform) against the one `femcod mkdeck self-affine` makes on one core
   !> (build_problem, then femcod_scene's gaps) with the same options, shape on either
   !> surface: every gap within 1e-12 of the height range (the two transforms round
   !> differently), and the same constants. NP 96 (even slabs) with the shape on the lower
   !> surface, NP 90 (23, 23, 23, 21 columns on 4 ranks) on the upper.
   subroutine test_generate(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_spec) :: spec
      type(contact_problem) :: deck, header
      type(status_type) :: status
      type(MPI_Comm) :: group
      real(dp), allocatable :: local(:, :), g0(:, :), whole(:, :)
      integer, allocatable :: firsts(:), counts(:)
      real(dp) :: constants(4), worst(1), range
      integer :: ranks, rank, group_size, group_rank, block, side, code(1)
      call MPI_Comm_size(MPI_COMM_WORLD, ranks)
      call MPI_Comm_rank(MPI_COMM_WORLD, rank)
      do side = 1, 2
         spec%kind = "self-affine"
         spec%label = "test"
         spec%np = merge(96, 90, side == 1)
         spec%pixel = 1.5_dp
         spec%hurst = 0.7_dp
         spec%rms = 2
         spec%seed = 11
         spec%shape_on = trim(merge("lower", "upper", side == 1))
         call build_problem(spec, deck, status)
         call check(error, status%code, 0, status%message)
         if (allocated(error)) return
         g0 = initial_gap_map(deck%lower, deck%upper)
         range = maxval(g0) - minval(g0)
         group_size = 1
         do while (group_size <= min(ranks, 4))
            call MPI_Comm_split(MPI_COMM_WORLD, merge(rank/group_size, MPI_UNDEFINED, rank/group_size < &
               ranks/group_size), rank, group)
            worst = 0
            code = 0
            if (group /= MPI_COMM_NULL) then
               call MPI_Comm_rank(group, group_rank)
               call generate_columns(spec, group, cg_settings(), header, local, constants, block, status)
               code(1) = status%code
               if (code(1) == 0) then
                  call column_split(spec%np, group_size, block, firsts, counts)
                  allocate(whole(spec%np, spec%np))
                  call MPI_Gatherv(local, spec%np*counts(group_rank), MPI_DOUBLE_PRECISION, whole, &
                     spec%np*counts, spec%np*firsts, MPI_DOUBLE_PRECISION, 0, group)
                  if (group_rank == 0) worst(1) = maxval(abs(whole - g0))/range + &
                     abs(constants(2) - deck%pixel) + abs(header%young(3) - deck%young(3))
                  deallocate(whole)
               end if
               call MPI_Comm_free(group)
            end if
            call MPI_Allreduce(MPI_IN_PLACE, worst, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
            call MPI_Allreduce(MPI_IN_PLACE, code, 1, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD)
            call check(error, code(1), 0, "generate on "//to_string(group_size)//" ranks")
            if (allocated(error)) return
            call check(error, worst(1) <= 1.0e-12_dp, "the surface on "//to_string(group_size)//" ranks, shape on "// &
               spec%shape_on//": largest gap difference "//to_string(worst(1))//" of the height range")
            if (allocated(error)) return
            group_size = 2*group_size
         end do
      end do
   end subroutine test_generate

   !> input/sphere_d05.deck (R = 15 nm, 0.5 nm pixels) at 1000 nN: Hertz's approach
   !> (eq. 4.14, femcod_analytic) within 1 %, the serial solver's tolerance (test_cg).
   subroutine test_hertz(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      type(distributed_grid) :: grid
      type(distributed_state), allocatable :: states(:)
      type(cg_settings) :: how
      type(distributed_observer) :: observer
      integer :: rank, block
      real(dp) :: estar
      call MPI_Comm_rank(MPI_COMM_WORLD, rank)
      if (rank == 0) call read_deck("../input/sphere_d05.deck", deck, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      how%tol = 1.0e-8_dp
      call distribute_problem(deck, MPI_COMM_WORLD, how, grid, block, status)
      if (status%code == 0) call solve_loads(grid, deck, [1000.0_dp], how, states, status, observer)
      call grid_free(grid)
      call check(error, status%code, 0)
      if (allocated(error)) return
      estar = 200/(1 - 0.25_dp**2)
      call check(error, states(1)%approach, hertz_approach(1000.0_dp, 15.0_dp, estar), rel=.true., thr=0.01_dp, &
         message="Hertz at 1000 nN")
   end subroutine test_hertz

   !> A self-affine surface (NP = 128: the coarse start at work) at two loads, on every
   !> sub-communicator of 1, 2 and 4 ranks the run has: the approach within 1e-10 of the
   !> height range of the serial cg solver's (femcod_cg, solved on each group's rank 0),
   !> and the same contact set, pixel by pixel (both at --tol 1e-12).
   subroutine test_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%loads = [3.0e3_dp, 2.0e4_dp]
      call against_serial(error, options)
   end subroutine test_against_serial

   !> The same at 256^2, where the coarse start's 128^2 grid is solved on the ranks
   !> (femcod_mpi_cg's ranks_coarse_solve, from its own 64^2 start on rank 0): loads on the
   !> free surface, approaches on the periodic cell.
   subroutine test_coarse_on_ranks(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%loads = [3.0e3_dp, 2.0e4_dp]
      call against_serial(error, options, 256)
      if (allocated(error)) return
      options = contact_options()
      options%boundary = BOUNDARY_PERIODIC
      options%approaches = [0.04_dp, 0.1_dp]
      call against_serial(error, options, 256)
   end subroutine test_coarse_on_ranks

   !> The same with the plastic cap at H = 10 GPa (below the elastic peak pressures of
   !> these loads, so that pixels cap): the plastic set as serial's too, pixel count and
   !> plastic volume (to 1e-9).
   subroutine test_plastic_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%loads = [3.0e3_dp, 2.0e4_dp]
      options%plastic = .true.
      options%hardness = 10
      call against_serial(error, options)
   end subroutine test_plastic_against_serial

   !> Displacement control: two approaches (2 and 6 % of the height range, in the order
   !> 6, 2), the loads found within 1e-8 of the serial solver's.
   subroutine test_approach_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%approaches = [0.06_dp, 0.02_dp]
      call against_serial(error, options)
   end subroutine test_approach_against_serial

   !> The kernel truncated to 12 pixels (--kernel-radius; no preconditioner where the
   !> truncated kernel's spectrum is not positive, on either side).
   subroutine test_truncated_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%loads = [3.0e3_dp, 2.0e4_dp]
      options%cg%kernel_radius = 12
      call against_serial(error, options)
   end subroutine test_truncated_against_serial

   !> The periodic cell (the kernel's spectrum in closed form on each rank's frequencies,
   !> femcod_love_periodic) at two loads with the plastic cap at 10 GPa.
   subroutine test_periodic_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%loads = [3.0e3_dp, 2.0e4_dp]
      options%boundary = BOUNDARY_PERIODIC
      options%plastic = .true.
      options%hardness = 10
      call against_serial(error, options)
   end subroutine test_periodic_against_serial

   !> Friction from the pressures (tau0 = 0.1 GPa, alpha = 0.3) with the plastic cap at
   !> 10 GPa, whose shear cap k = H/(3 sqrt 3) = 1.92 GPa binds above 6.1 GPa: the
   !> friction force, a sum over each rank's contacts, within 1e-8 of the serial one.
   subroutine test_friction_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%loads = [3.0e3_dp, 2.0e4_dp]
      options%plastic = .true.
      options%hardness = 10
      options%shear = .true.
      options%shear_strength = 0.1_dp
      options%shear_slope = 0.3_dp
      call against_serial(error, options)
   end subroutine test_friction_against_serial

   !> The tangential step after the normal one (solvers/femcod_tangential through
   !> femcod_mpi_shear's operator): a force of 900 nN (mu = 0.5: 0.6 mu P at the first load,
   !> 0.09 mu P at the second; partial slip, some pixels sticking, some slipping), the
   !> shift, the force and every traction within 1e-8 of the serial step's (the largest
   !> traction's), the same stick map pixel for pixel.
   subroutine test_tangential_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%loads = [3.0e3_dp, 2.0e4_dp]
      options%tangential = .true.
      options%friction = 0.5_dp
      options%tangential_load = 900
      call against_serial(error, options)
   end subroutine test_tangential_against_serial

   !> The 64^2 self-affine deck of the tests below (2 nm pixels, seed 3).
   subroutine rough_deck_64(deck, status)
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      spec%kind = "self-affine"
      spec%label = "test"
      spec%np = 64
      spec%pixel = 2
      spec%seed = 3
      call build_problem(spec, deck, status)
   end subroutine rough_deck_64

   !> gather_block_maxima (femcod-mpi's figures): on a 64^2 grid split over the ranks,
   !> blocks of 1, 3 and 5 columns (3 and 5 do not divide a rank's 32 or 16 columns, so
   !> blocks lie across two ranks), rank 0's blocks equal the largest value of each block
   !> of the whole map, taken directly (every rank knows the whole map here: pseudo-random
   !> values, frac(43758.5453 sin(12.9898 i + 78.233 j)), so that a block's largest value
   !> lies in either rank's part of it).
   subroutine test_block_maxima(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(cg_settings) :: how
      type(status_type) :: status
      type(distributed_grid) :: grid
      real(dp), allocatable :: whole(:, :), blocks(:, :)
      real(dp) :: bad(1)
      integer :: block, i, j, f, m, k
      integer, parameter :: widths(3) = [1, 3, 5]
      call rough_deck_64(deck, status)
      call distribute_problem(deck, MPI_COMM_WORLD, how, grid, block, status, .false.)
      call check(error, status%code, 0)
      if (allocated(error)) return
      allocate(whole(64, 64))
      do j = 1, 64
         do i = 1, 64
            whole(i, j) = modulo(43758.5453_dp*sin(12.9898_dp*i + 78.233_dp*j), 1.0_dp)
         end do
      end do
      bad = 0
      do k = 1, size(widths)
         f = widths(k)
         call gather_block_maxima(grid, whole(:, grid%j0 + 1:grid%j0 + grid%nj), f, blocks)
         if (grid%rank /= 0) cycle
         m = (64 + f - 1)/f
         if (any(shape(blocks) /= [m, m])) then
            bad = bad + 1
            cycle
         end if
         do j = 1, m
            do i = 1, m
               if (blocks(i, j) /= maxval(whole((i - 1)*f + 1:min(64, i*f), (j - 1)*f + 1:min(64, j*f)))) bad = bad + 1
            end do
         end do
      end do
      call grid_free(grid)
      call MPI_Allreduce(MPI_IN_PLACE, bad, 1, MPI_DOUBLE_PRECISION, MPI_SUM, MPI_COMM_WORLD)
      call check(error, nint(bad(1)), 0, "blocks unlike the whole map's block maxima")
   end subroutine test_block_maxima

   !> femcod-mpi's observer (femcod_mpi_observer) writes each state's columns into the
   !> result file as soon as the state is solved, then frees them. Loads given out of order
   !> (20000, 3000, 8000 nN; the plastic cap; a tangential step after the states) on all
   !> ranks, once with the base observer that keeps the columns and once streamed, the
   !> maps written in blocks of 100 values (several a map): each /loads/<k>'s pressure,
   !> gap and plastic displacement equal to the kept columns of state k, bit for bit (the
   !> same solve; a map under another state's name, or a block in the wrong place,
   !> differs), the streamed states' columns gone, and the tangential step, which ran on
   !> the contact lists the observer kept, with the kept columns' answer.
   subroutine test_streamed_columns(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(status_type) :: status
      type(distributed_grid) :: grid
      type(distributed_state), allocatable :: kept(:), streamed(:)
      type(distributed_observer) :: keeper
      type(signal_observer) :: streamer
      type(h5_file) :: file
      real(dp), allocatable :: map(:, :)
      real(dp) :: bad(3)
      character(len=:), allocatable :: path, g
      integer :: block, k, rank, ranks, stage
      call MPI_Comm_rank(MPI_COMM_WORLD, rank)
      call MPI_Comm_size(MPI_COMM_WORLD, ranks)
      call rough_deck_64(deck, status)
      options%solver = SOLVER_CG
      options%loads = [2.0e4_dp, 3.0e3_dp, 8.0e3_dp]
      options%plastic = .true.
      options%hardness = 10
      options%tangential = .true.
      options%friction = 0.5_dp
      options%tangential_load = 900
      options%cg%tol = 1.0e-12_dp
      path = "test_streamed_"//to_string(ranks)//".h5.part"
      do stage = 1, 2
         call distribute_problem(deck, MPI_COMM_WORLD, options%cg, grid, block, status, .false.)
         if (stage == 1) then
            call solve_and_shear(kept, keeper)
         else
            streamer%path = path
            streamer%tangential = .true.
            streamer%block_values = 100
            call begin_distributed_results(path, grid, size(options%loads), status)
            call solve_and_shear(streamed, streamer)
         end if
         if (stage == 1 .or. status%code /= 0) call grid_free(grid)
      end do
      if (status%code /= 0) call check(error, status%code, 0, "the solves and the writes: "//status%message)
      if (allocated(error)) then
         if (rank == 0) call remove_file(path)
         return
      end if
      bad = 0
      do k = 1, size(options%loads)
         g = load_group(k, size(options%loads))
         if (allocated(streamed(k)%force) .or. allocated(streamed(k)%gap) .or. allocated(streamed(k)%plastic)) &
            bad(1) = bad(1) + 1
         call h5_open(path, file, status, 3)
         call h5_read(file, g//"/pressure", map, status, 3)
         if (status%code == 0) bad(2) = bad(2) + count(map(:, grid%j0 + 1:grid%j0 + grid%nj) /= &
            kept(k)%force/grid%pixel**2)
         call h5_read(file, g//"/gap", map, status, 3)
         if (status%code == 0) bad(2) = bad(2) + count(map(:, grid%j0 + 1:grid%j0 + grid%nj) /= kept(k)%gap)
         call h5_read(file, g//"/plastic_displacement", map, status, 3)
         if (status%code == 0) bad(2) = bad(2) + count(map(:, grid%j0 + 1:grid%j0 + grid%nj) /= kept(k)%plastic)
         call h5_close(file, status)
         if (status%code /= 0) bad(2) = bad(2) + 1
         if (kept(k)%stick_contacts /= streamed(k)%stick_contacts .or. size(kept(k)%shear_x) /= &
            size(streamed(k)%shear_x)) then
            bad(3) = bad(3) + 1
         else if (any(kept(k)%shear_x /= streamed(k)%shear_x) .or. any(kept(k)%shear_y /= streamed(k)%shear_y)) then
            bad(3) = bad(3) + 1
         end if
      end do
      call grid_free(grid)
      call MPI_Allreduce(MPI_IN_PLACE, bad, 3, MPI_DOUBLE_PRECISION, MPI_SUM, MPI_COMM_WORLD)
      call MPI_Barrier(MPI_COMM_WORLD)
      if (rank == 0) call remove_file(path)
      call check(error, nint(bad(1)), 0, "states whose columns stayed in memory")
      if (allocated(error)) return
      call check(error, nint(bad(2)), 0, "map values in the file unlike the kept columns (or unreadable maps)")
      if (allocated(error)) return
      call check(error, nint(bad(3)), 0, "states whose tangential answer differs from the kept columns'")
   contains
      subroutine solve_and_shear(states, observer)
         type(distributed_state), allocatable, intent(out) :: states(:)
         class(distributed_observer), intent(inout) :: observer
         if (status%code == 0) call solve_loads(grid, deck, options%loads, options%cg, states, status, observer, &
            options%hardness, options%plastic, .false., make_interface_law(options%adhesion, options%work, &
            options%range, deck%pixel, options%plastic, options%hardness), run_shear_model(options))
         if (status%code == 0) call tangential_on_ranks(grid, deck, tangential_request_of(options), states, status, &
            observer)
      end subroutine solve_and_shear
   end subroutine test_streamed_columns

   !> The same on the periodic cell under a rigid shift (slip control, 0.05 nm: partial
   !> slip at both loads), the Cerruti spectra in closed form on each rank's frequencies.
   subroutine test_periodic_slip_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%loads = [3.0e3_dp, 2.0e4_dp]
      options%boundary = BOUNDARY_PERIODIC
      options%tangential = .true.
      options%by_slip = .true.
      options%friction = 0.5_dp
      options%slip = 0.05_dp
      call against_serial(error, options)
   end subroutine test_periodic_slip_against_serial

   !> The periodic cell under displacement control (the fall of the mean gap; 2 and 6 %
   !> of the height range, below the mean gap).
   subroutine test_periodic_approach_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%approaches = [0.02_dp, 0.06_dp]
      options%boundary = BOUNDARY_PERIODIC
      call against_serial(error, options)
   end subroutine test_periodic_approach_against_serial

   !> Adhesion (the exponential law, W = 0.05 J/m^2, R = 2 nm, one pixel) along a path that
   !> loads to 6 % of the height range, unloads and pulls apart, on the free surface: the
   !> gap variables on the distributed transform grid (femcod_mpi_gap_transform, the
   !> padding columns beside each rank's own) against the serial solver's.
   subroutine test_adhesion_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%approaches = [0.02_dp, 0.06_dp, 0.02_dp, -0.01_dp]
      options%adhesion = LAW_EXPONENTIAL
      options%work = 0.05_dp
      options%range = 2
      call against_serial(error, options)
   end subroutine test_adhesion_against_serial

   !> Dugdale's law with the plastic cap at 10 GPa on the periodic cell (no padding; the
   !> mean gap a constraint), loading and unloading.
   subroutine test_periodic_adhesion_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%approaches = [0.03_dp, 0.08_dp, 0.03_dp]
      options%boundary = BOUNDARY_PERIODIC
      options%adhesion = LAW_DUGDALE
      options%work = 0.05_dp
      options%range = 2
      options%plastic = .true.
      options%hardness = 10
      call against_serial(error, options)
   end subroutine test_periodic_adhesion_against_serial

   !> The hard wall with the cap under displacement control (the gap variables, no law).
   subroutine test_plastic_approach_against_serial(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options) :: options
      options%approaches = [0.03_dp, 0.08_dp, 0.05_dp]
      options%plastic = .true.
      options%hardness = 10
      call against_serial(error, options)
   end subroutine test_plastic_approach_against_serial

   !> femcod-mpi's solve_loads with `options` (approaches given as fractions of the height
   !> range) against the serial solve_contact, on groups of 1, 2 and 4 ranks. The
   !> contacts: the pixels with a force (the gaps at 0 in the gap variables, where a
   !> contact may pull); loads relative to the serial one's (the largest |load| of the
   !> path in the gap variables, where a load may pass through 0).
   subroutine against_serial(error, options, side)
      type(error_type), allocatable, intent(out) :: error
      type(contact_options), intent(inout) :: options
      !> The grid's side (default 128).
      integer, intent(in), optional :: side
      integer :: np
      type(scene_spec) :: spec
      type(contact_problem) :: deck
      type(contact_result) :: res
      type(status_type) :: status, serial_status
      type(distributed_grid) :: grid
      type(distributed_state), allocatable :: states(:)
      type(distributed_observer) :: observer
      type(MPI_Comm) :: group
      real(dp), allocatable :: forces(:, :)
      integer, allocatable :: firsts(:), counts(:)
      integer :: ranks, rank, group_size, group_rank, block, k, worst_code
      real(dp) :: range, bad(7), load_scale
      real(dp), allocatable :: targets(:)
      logical :: by_approach, by_gaps
      np = 128
      if (present(side)) np = side
      call MPI_Comm_size(MPI_COMM_WORLD, ranks)
      call MPI_Comm_rank(MPI_COMM_WORLD, rank)
      spec%kind = "self-affine"
      spec%label = "test"
      spec%np = np
      spec%pixel = 2
      spec%seed = 3
      call build_problem(spec, deck, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      range = maxval(deck%upper) - minval(deck%upper)
      options%solver = SOLVER_CG
      by_approach = .false.
      if (allocated(options%approaches)) by_approach = size(options%approaches) > 0
      if (by_approach) then
         options%approaches = options%approaches*range
         targets = options%approaches
      else
         targets = options%loads
      end if
      options%cg%tol = 1.0e-12_dp
      options%cg%max_iterations = 5000
      by_gaps = by_approach .and. (options%plastic .or. options%adhesion /= LAW_HARD_WALL)
      group_size = 1
      do while (group_size <= min(ranks, 4))
         ! Groups of `group_size` ranks (the ranks beyond the last whole group sit this one out).
         call MPI_Comm_split(MPI_COMM_WORLD, merge(rank/group_size, MPI_UNDEFINED, rank/group_size < ranks/group_size), rank, group)
         bad = 0
         worst_code = 0
         if (group /= MPI_COMM_NULL) then
            call MPI_Comm_rank(group, group_rank)
            call distribute_problem(deck, group, options%cg, grid, block, status, options%boundary == BOUNDARY_PERIODIC)
            if (status%code == 0) call solve_loads(grid, deck, targets, options%cg, states, status, observer, &
               options%hardness, options%plastic, by_approach, make_interface_law(options%adhesion, options%work, &
               options%range, deck%pixel, options%plastic, options%hardness), run_shear_model(options))
            if (status%code == 0 .and. options%tangential) call tangential_on_ranks(grid, deck, &
               tangential_request_of(options), states, status, observer)
            worst_code = status%code
            if (group_rank == 0) call solve_contact(deck, options, res, serial_status)
            if (group_rank == 0) worst_code = max(worst_code, serial_status%code)
            if (worst_code == 0) then
               call column_split(np, group_size, block, firsts, counts)
               if (group_rank == 0) load_scale = maxval(abs(res%states%load))
               do k = 1, size(targets)
                  allocate(forces(np, np))
                  ! The contact map, 1 on a contact: the pixels with a force, or at gap 0.
                  if (by_gaps) then
                     call MPI_Gatherv(merge(1.0_dp, 0.0_dp, states(k)%gap == 0), np*counts(group_rank), &
                        MPI_DOUBLE_PRECISION, forces, np*counts, np*firsts, MPI_DOUBLE_PRECISION, 0, group)
                  else
                     call MPI_Gatherv(states(k)%force, np*counts(group_rank), MPI_DOUBLE_PRECISION, forces, &
                        np*counts, np*firsts, MPI_DOUBLE_PRECISION, 0, group)
                  end if
                  if (group_rank == 0) then
                     bad(1) = max(bad(1), abs(states(k)%approach - res%states(k)%approach)/range)
                     bad(2) = bad(2) + count_differences(forces, res%states(k)%i, res%states(k)%j)
                     bad(3) = bad(3) + abs(states(k)%contacts - res%states(k)%contacts)
                     if (.not. by_gaps) load_scale = res%states(k)%load
                     bad(4) = max(bad(4), abs(states(k)%load - res%states(k)%load)/load_scale, &
                        abs(states(k)%friction - res%states(k)%friction)/max(abs(res%states(k)%friction), 1.0e-300_dp))
                     ! With the shear model, the friction must be there, or the test shows nothing.
                     if (options%shear .and. .not. res%states(k)%friction > 0) bad(4) = 1
                     ! Adhesion: the path must reach contact, or the test shows nothing.
                     if (by_gaps .and. k == 2 .and. res%states(k)%contacts == 0) bad(3) = bad(3) + 1
                     ! With the cap, the last load must cap pixels, or the test shows nothing.
                     if (options%plastic .and. k == 2 .and. res%states(k)%n_plastic == 0) bad(5) = bad(5) + 1
                     bad(5) = bad(5) + abs(states(k)%n_plastic - res%states(k)%n_plastic) + &
                        abs(states(k)%plastic_volume - res%states(k)%plastic_volume)/ &
                        max(res%states(k)%plastic_volume, 1.0e-300_dp)*1.0e9_dp
                  end if
                  deallocate(forces)
                  if (options%tangential) call tangential_differences(grid, group, states(k), res%states(k), bad(6:7))
               end do
            end if
            call grid_free(grid)
            call MPI_Comm_free(group)
         end if
         call MPI_Allreduce(MPI_IN_PLACE, bad, 7, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
         call MPI_Allreduce(MPI_IN_PLACE, worst_code, 1, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD)
         call check(error, worst_code, 0, "solve on "//to_string(group_size)//" ranks")
         if (allocated(error)) return
         call check(error, bad(1) <= 1.0e-10_dp, "approach on "//to_string(group_size)//" ranks off by "// &
            to_string(bad(1))//" of the height range")
         if (allocated(error)) return
         call check(error, bad(2) == 0 .and. bad(3) == 0, "contact sets on "//to_string(group_size)//" ranks: "// &
            to_string(nint(bad(2)))//" pixels differ")
         if (allocated(error)) return
         call check(error, bad(4) <= 1.0e-8_dp, "load or friction on "//to_string(group_size)//" ranks off by "// &
            to_string(bad(4))//" of the serial one")
         if (allocated(error)) return
         call check(error, bad(5) < 1, "plastic set or volume on "//to_string(group_size)//" ranks differs (n "// &
            "plastic differences + 1e9 x relative volume difference = "//to_string(bad(5))//")")
         if (allocated(error)) return
         call check(error, bad(6) <= 1.0e-8_dp .and. bad(7) == 0, "tangential step on "//to_string(group_size)// &
            " ranks: shift, force or tractions off by "//to_string(bad(6))//" of the serial ones, "// &
            to_string(nint(bad(7)))//" pixels stick otherwise (or no partial slip to compare)")
         if (allocated(error)) return
         group_size = 2*group_size
      end do
   contains
      !> Pixels in contact in one answer and not in the other.
      real(dp) function count_differences(forces, ci, cj) result(n)
         real(dp), intent(in) :: forces(:, :)
         integer, intent(in) :: ci(:), cj(:)
         logical, allocatable :: serial(:, :)
         integer :: q
         allocate(serial(np, np))
         serial = .false.
         do q = 1, size(ci)
            serial(ci(q), cj(q)) = .true.
         end do
         n = count(serial .neqv. forces > 0)
      end function count_differences
   end subroutine against_serial

   !> On the group's rank 0, into bad(1) the largest difference of the ranks' tangential
   !> step from the serial one's (shift and force relative to their size, tractions to
   !> the largest), into bad(2) the pixels whose stick differs (1 more where the serial
   !> state has no partial slip: nothing to compare). Collective over `group`.
   subroutine tangential_differences(grid, group, st, serial, bad)
      use femcod_contact_result, only: load_state
      type(distributed_grid), intent(in) :: grid
      type(MPI_Comm), intent(in) :: group
      type(distributed_state), intent(in) :: st
      type(load_state), intent(in) :: serial
      real(dp), intent(inout) :: bad(2)
      real(dp), allocatable :: local(:, :, :), whole(:, :, :)
      integer :: n, np
      np = grid%np
      allocate(local(np, grid%nj, 2), whole(np, np, 2))
      local = 0
      do n = 1, size(st%stick)
         local(st%tangential_i(n), st%tangential_j(n), :) = [st%shear_x(n), merge(1.0_dp, 0.0_dp, st%stick(n))]
      end do
      do n = 1, 2
         call MPI_Gatherv(local(:, :, n), np*grid%nj, MPI_DOUBLE_PRECISION, whole(:, :, n), np*grid%count, &
            np*grid%first, MPI_DOUBLE_PRECISION, 0, group)
      end do
      if (grid%rank /= 0) return
      bad(1) = max(bad(1), abs(st%tangential_shift(1) - serial%tangential_shift(1))/abs(serial%tangential_shift(1)), &
         abs(st%tangential_force(1) - serial%tangential_force(1))/abs(serial%tangential_force(1)), &
         maxval(abs([(whole(serial%i(n), serial%j(n), 1) - serial%shear_x(n), n = 1, size(serial%i))]))/ &
         maxval(abs(serial%shear_x)))
      bad(2) = bad(2) + count([(whole(serial%i(n), serial%j(n), 2) > 0 .neqv. serial%stick(n), n = 1, size(serial%i))]) &
         + abs(sum(whole(:, :, 2)) - count(serial%stick))
      if (count(serial%stick) == 0 .or. all(serial%stick)) bad(2) = bad(2) + 1
   end subroutine tangential_differences
end module test_distributed
