!> The elastic operator: the surface's displacements (nm) from its contact forces (nN) on
!> an NP x NP grid of pixels, w = c (I * F), with I the Love table (the free half-space's,
!> zero-padded, or the periodic cell's; optionally truncated to --kernel-radius), c the
!> composite compliance (nm/nN), and beside it the springs' compliance s (nm/nN) on the
!> diagonal, the pixel's own coefficient I(0, 0), the gaps g0 (nm) and their range, and the
!> preconditioner's stencil taps (femcod_convolution's inverse_kernel_taps).
!>
!> One process holds the columns j0 + 1 .. j0 + nj of the grid: all of them on one core
!> (grid_operator, here), a slab on MPI ranks (mpi/src extends this type). So every sum,
!> maximum and minimum a solver takes over the grid goes through the operator's
!> reductions (on one core the value itself, on ranks an all-reduce), and the stencil's
!> two columns beyond the slab through exchange_halo. The constrained iteration
!> (solvers/femcod_cg) is written once against this type.
!>
!> The grid operator can also correct displacements for a few changed forces without a
!> convolution (directly from the table, or by the kernel split of
!> femcod_split_correction); an operator that cannot says so through correction_limits
!> (0, 0), and the iteration then convolves afresh.
!>
!> No I/O and no stop.
module femcod_elastic_operator
   use femcod_kinds, only: dp, sp
   use femcod_problem, only: contact_problem
   use femcod_solver_options, only: cg_settings
   use femcod_love, only: offset_table, surface_compliance
   use femcod_love_periodic, only: periodic_offset_table
   use femcod_spring, only: spring_stiffness
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_apply_single, &
      convolution_free, inverse_kernel_taps, gap_transform, gap_transform_setup, gap_transform_apply, &
      gap_transform_free, SPECTRUM_COMPLIANCE, SPECTRUM_STIFFNESS
   use femcod_split_correction, only: split_correction, split_setup, split_apply, split_free
   use femcod_status, only: status_type
   use femcod_observer, only: solver_observer
   implicit none
   private
   public :: elastic_operator, grid_operator, grid_operator_setup, grid_operator_free, truncate_table, spread_load
   public :: cg_constraint, kernel_split_limit, split_within_allowance, copy_and_displace_single
   public :: SPECTRUM_COMPLIANCE, SPECTRUM_STIFFNESS, TABLE_NONE, TABLE_SINGLE, TABLE_DOUBLE

   !> Which Love table a grid operator keeps besides its convolution (grid_operator_setup's
   !> `tables`): none (the maps' operator), the float32 one for the cg family's direct
   !> corrections and kernel split, or the double one for the event solvers' exact
   !> evaluations.
   integer, parameter :: TABLE_NONE = 0, TABLE_SINGLE = 1, TABLE_DOUBLE = 2

   !> What a constrained solve holds fixed (solvers/femcod_constrained_cg): the total load
   !> `value` (nN), or with `by_approach` the approach `value` (nm, from the first touch,
   !> where the lowest initial gap is 0): load or displacement control.
   type :: cg_constraint
      real(dp) :: value = 0
      logical :: by_approach = .false.
   end type cg_constraint

   !> What every elastic operator has and does (module header).
   type, abstract :: elastic_operator
      !> Grid side; this part's first column (0-based) and number of columns.
      integer :: np = 0, j0 = 0, nj = 0
      !> The grid is one cell of a periodic surface (periodic table, cyclic convolution).
      logical :: periodic = .false.
      !> Pixel (nm), compliance c and the springs' s (nm/nN), the gaps' range over the
      !> whole grid (nm), I(0, 0) (dimensionless).
      real(dp) :: pixel = 0, c = 0, s = 0, scale = 1, self = 0
      !> This part's initial gaps (nm), (np, nj).
      real(dp), allocatable :: g0(:, :)
      !> Preconditioner taps; `preconditioned` false: none.
      logical :: preconditioned = .false.
      real(dp) :: taps(0:2, 0:2) = 0
      !> The gap-variable iteration's transform grid, where the operator has one (made on
      !> request; apply_spectrum): this part's field is (tm, tmj), of which the first np
      !> rows of the first nj columns are this part's pixels, the rest padding (none on a
      !> periodic cell). tm = 0: none. The smallest value of C's spectrum over the whole
      !> grid (nm/nN; the iteration needs it positive).
      integer :: tm = 0, tmj = 0
      real(dp) :: smallest_compliance = 0
   contains
      !> out = c (I * f) on this part's columns, in double.
      procedure(displace_interface), deferred :: displace
      !> The same in float32 transforms, into out (double) or out32.
      procedure(displace_single_interface), deferred :: displace_single
      !> f (nN) replaced by c (I * f) (nm), in double, and the same for a float32 f by
      !> float32 transforms: the search direction's displacements formed in the storage
      !> its forces were scattered into. The base copies f first; an operator whose
      !> transforms read all of f before they write overrides them with no copy.
      procedure :: displace_in_place => copy_and_displace
      procedure :: displace_single_in_place => copy_and_displace_single
      !> values(:), this part's sums or maxima or minima, become the whole grid's.
      procedure :: sum_over_grid => local_reduction
      procedure :: max_over_grid => local_reduction
      procedure :: min_over_grid => local_reduction
      !> True on every part when `flag` is true on one (every part takes the same branch).
      procedure :: any_over_grid => local_any
      !> The stencil's two columns on each side of this part (zero beyond the grid).
      procedure :: exchange_halo => no_halo
      !> How many changed forces add_direct and split_correct take (0: none).
      procedure :: correction_limits => no_corrections
      procedure :: add_direct => no_direct
      procedure :: split_correct => no_split
      !> The forces (nN) a solve under a constraint starts from (spread_load; femcod-mpi's
      !> operator starts from a coarse solve).
      procedure :: start_forces => spread_start
      !> out = C in or K in (which: SPECTRUM_COMPLIANCE or SPECTRUM_STIFFNESS) on this
      !> part's transform field (tm, tmj); K = C^-1, both with the springs' s.
      procedure :: apply_spectrum => no_spectrum
   end type elastic_operator

   abstract interface
      subroutine displace_interface(op, f, out)
         import :: elastic_operator, dp
         class(elastic_operator), intent(inout) :: op
         real(dp), intent(in) :: f(:, :)
         real(dp), intent(out) :: out(:, :)
      end subroutine displace_interface

      subroutine displace_single_interface(op, f, out, out32)
         import :: elastic_operator, dp, sp
         class(elastic_operator), intent(inout) :: op
         real(dp), intent(in) :: f(:, :)
         real(dp), intent(out), optional :: out(:, :)
         real(sp), intent(out), optional :: out32(:, :)
      end subroutine displace_single_interface
   end interface

   !> The whole grid in one process: the free surface or the periodic cell, by FFTW
   !> (femcod_convolution), with the float32 Love table for direct corrections and the
   !> kernel split.
   type, extends(elastic_operator) :: grid_operator
      !> The Love table I(0:np-1, 0:np-1) rounded to float32 (TABLE_SINGLE, the cg family's;
      !> its double is needed only to set up the convolution; at NP = 4096 the float32
      !> table is 67 MB), or in double (TABLE_DOUBLE, the event solvers': dimensionless).
      real(sp), allocatable :: table(:, :)
      real(dp), allocatable :: exact(:, :)
      type(love_convolution) :: conv
      type(split_correction) :: split
      !> The kernel is truncated (--kernel-radius): no kernel split.
      logical :: truncated = .false.
      !> The gap-variable iteration's transform grid (set up with gap_variables).
      type(gap_transform) :: gaps
   contains
      procedure :: displace => grid_displace
      procedure :: displace_single => grid_displace_single
      procedure :: displace_in_place => grid_displace_in_place
      procedure :: displace_single_in_place => grid_displace_single_in_place
      procedure :: correction_limits => grid_correction_limits
      procedure :: add_direct => grid_add_direct
      procedure :: split_correct => grid_split_correct
      procedure :: apply_spectrum => grid_apply_spectrum
   end type grid_operator

contains

   !> f replaced by c (I * f) through displace, from a copy of f.
   subroutine copy_and_displace(op, f)
      class(elastic_operator), intent(inout) :: op
      real(dp), intent(inout) :: f(:, :)
      real(dp), allocatable :: copy(:, :)
      copy = f
      call op%displace(copy, f)
   end subroutine copy_and_displace

   !> The float32 f replaced by c (I * f) through displace_single, from a copy of f in
   !> double (the transforms round it back to the same float32 values).
   subroutine copy_and_displace_single(op, f32)
      class(elastic_operator), intent(inout) :: op
      real(sp), intent(inout) :: f32(:, :)
      real(dp), allocatable :: copy(:, :)
      copy = real(f32, dp)
      call op%displace_single(copy, out32=f32)
   end subroutine copy_and_displace_single

   subroutine local_reduction(op, values)
      class(elastic_operator), intent(inout) :: op
      real(dp), intent(inout) :: values(:)
   end subroutine local_reduction

   logical function local_any(op, flag)
      class(elastic_operator), intent(inout) :: op
      logical, intent(in) :: flag
      local_any = flag
   end function local_any

   subroutine no_halo(op, gm)
      class(elastic_operator), intent(inout) :: op
      real(sp), intent(inout) :: gm(-1:, -1:)
   end subroutine no_halo

   subroutine no_corrections(op, how, limit, split_limit)
      class(elastic_operator), intent(in) :: op
      type(cg_settings), intent(in) :: how
      integer, intent(out) :: limit, split_limit
      limit = 0
      split_limit = 0
   end subroutine no_corrections

   subroutine no_direct(op, w, changed, delta, n)
      class(elastic_operator), intent(in) :: op
      real(dp), intent(inout) :: w(:, :)
      integer, intent(in) :: changed(:, :)
      real(dp), intent(in) :: delta(:)
      integer, intent(in) :: n
   end subroutine no_direct

   subroutine no_split(op, w, changed, delta, n, how, allowance, split_error, applied)
      class(elastic_operator), intent(inout) :: op
      real(dp), intent(inout) :: w(:, :)
      integer, intent(in) :: changed(:, :)
      real(dp), intent(in) :: delta(:)
      integer, intent(in) :: n
      type(cg_settings), intent(in) :: how
      real(dp), intent(in) :: allowance
      real(dp), intent(inout) :: split_error
      logical, intent(out) :: applied
      applied = .false.
   end subroutine no_split

   subroutine no_spectrum(op, which, in, out)
      class(elastic_operator), intent(inout) :: op
      integer, intent(in) :: which
      real(dp), intent(in) :: in(:, :)
      real(dp), intent(out) :: out(:, :)
      ! An operator without a transform grid (tm = 0): the iteration checks tm first.
      out = 0
   end subroutine no_spectrum

   !> The start of a solve under `target`: spread_load. `coarse_iterations`, the
   !> iterations a coarse solve took (none here), is added to.
   subroutine spread_start(op, target, how, p, coarse_iterations, status, observer)
      class(elastic_operator), intent(inout) :: op
      type(cg_constraint), intent(in) :: target
      type(cg_settings), intent(in) :: how
      real(dp), intent(out) :: p(:, :)
      integer, intent(inout) :: coarse_iterations
      type(status_type), intent(inout) :: status
      class(solver_observer), intent(inout) :: observer
      call spread_load(op, target, p)
   end subroutine spread_start

   !> A first guess of the forces (nN) under `target`. A load P: spread evenly over the
   !> pixels within a tenth of the height range of the first touch (the lowest gap of the
   !> whole grid). An approach A: each pixel that overlaps, g0 < A, pushed back by half
   !> its own stiffness, (A - g0) / (2 (c I(0,0) + s)) (alone it would take the whole).
   subroutine spread_load(op, target, p)
      class(elastic_operator), intent(inout) :: op
      type(cg_constraint), intent(in) :: target
      real(dp), intent(out) :: p(:, :)
      real(dp) :: lowest(1), n(1)
      if (target%by_approach) then
         p = max(target%value - op%g0, 0.0_dp)/(2*(op%c*op%self + op%s))
         return
      end if
      lowest(1) = minval(op%g0)
      call op%min_over_grid(lowest)
      where (op%g0 <= lowest(1) + 0.1_dp*op%scale)
         p = 1
      elsewhere
         p = 0
      end where
      n(1) = sum(p)
      call op%sum_over_grid(n)
      p = p*(target%value/n(1))
   end subroutine spread_load

   !> The grid operator for gaps g0 (nm) with pixel size `pixel` (nm) and the deck's
   !> materials, one cell of a periodic surface when `periodic`; the kernel truncated to
   !> how%kernel_radius pixels of the deck's pixel (scaled to this grid's pixel). With
   !> `gap_variables` the operator has the gap-variable iteration's transform grid
   !> (apply_spectrum) instead of the convolution (displace). `tables` (TABLE_SINGLE by
   !> default): the Love table it keeps besides.
   subroutine grid_operator_setup(op, g0, problem, pixel, how, periodic, gap_variables, tables)
      type(grid_operator), intent(inout) :: op
      real(dp), intent(in) :: g0(:, :)
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: pixel
      type(cg_settings), intent(in) :: how
      logical, intent(in) :: periodic
      logical, intent(in), optional :: gap_variables
      integer, intent(in), optional :: tables
      real(dp), allocatable :: table(:, :)
      logical :: ok
      integer :: keep
      op%np = size(g0, 1)
      op%j0 = 0
      op%nj = size(g0, 2)
      op%periodic = periodic
      op%pixel = pixel
      op%g0 = g0
      op%c = surface_compliance(problem%young(1), problem%poisson(1), pixel) + &
         surface_compliance(problem%young(2), problem%poisson(2), pixel)
      op%s = 3/spring_stiffness(problem%young(3), problem%poisson(3), pixel, pixel)
      op%scale = max(maxval(g0) - minval(g0), tiny(1.0_dp))
      allocate(table(0:op%np - 1, 0:op%np - 1))
      if (periodic) then
         table(:, :) = periodic_offset_table(op%np)
      else
         table(:, :) = offset_table(op%np)
      end if
      op%truncated = how%kernel_radius > 0
      if (op%truncated) call truncate_table(table, how%kernel_radius*problem%pixel/pixel)
      op%self = table(0, 0)
      if (present(gap_variables)) then
         if (gap_variables) then
            call gap_transform_setup(op%gaps, table, op%c, op%s, periodic, ok, op%smallest_compliance)
            op%tm = op%gaps%m
            op%tmj = op%gaps%m
            return
         end if
      end if
      call convolution_setup(op%conv, table, how%single_until > 0, how%measure_plans, periodic)
      if (how%precondition) call inverse_kernel_taps(op%conv, op%taps, op%preconditioned)
      keep = TABLE_SINGLE
      if (present(tables)) keep = tables
      if (keep == TABLE_SINGLE) then
         allocate(op%table(0:op%np - 1, 0:op%np - 1))
         op%table(:, :) = real(table, sp)
      else if (keep == TABLE_DOUBLE) then
         call move_alloc(table, op%exact)
      end if
   end subroutine grid_operator_setup

   !> The plans and transform memory freed.
   subroutine grid_operator_free(op)
      type(grid_operator), intent(inout) :: op
      call convolution_free(op%conv)
      call split_free(op%split)
      call gap_transform_free(op%gaps)
      if (allocated(op%table)) deallocate(op%table)
      if (allocated(op%exact)) deallocate(op%exact)
   end subroutine grid_operator_free

   !> The kernel truncated: entries at offsets beyond `radius` pixels set to 0 (--kernel-
   !> radius, in the finest grid's pixels; a coarser grid's radius is scaled to its pixel).
   pure subroutine truncate_table(table, radius)
      real(dp), intent(inout) :: table(0:, 0:)
      real(dp), intent(in) :: radius
      integer :: p, q
      do q = 0, size(table, 2) - 1
         do p = 0, size(table, 1) - 1
            if (real(p, dp)**2 + real(q, dp)**2 > radius**2) table(p, q) = 0
         end do
      end do
   end subroutine truncate_table

   subroutine grid_displace(op, f, out)
      class(grid_operator), intent(inout) :: op
      real(dp), intent(in) :: f(:, :)
      real(dp), intent(out) :: out(:, :)
      call convolution_apply(op%conv, f, out, op%c)
   end subroutine grid_displace

   subroutine grid_displace_single(op, f, out, out32)
      class(grid_operator), intent(inout) :: op
      real(dp), intent(in) :: f(:, :)
      real(dp), intent(out), optional :: out(:, :)
      real(sp), intent(out), optional :: out32(:, :)
      if (present(out32)) then
         call convolution_apply_single(op%conv, f, factor=op%c, result32=out32)
      else
         call convolution_apply_single(op%conv, f, out, op%c)
      end if
   end subroutine grid_displace_single

   subroutine grid_displace_in_place(op, f)
      class(grid_operator), intent(inout) :: op
      real(dp), intent(inout) :: f(:, :)
      call convolution_apply(op%conv, factor=op%c, in_place=f)
   end subroutine grid_displace_in_place

   subroutine grid_displace_single_in_place(op, f32)
      class(grid_operator), intent(inout) :: op
      real(sp), intent(inout) :: f32(:, :)
      call convolution_apply_single(op%conv, factor=op%c, in_place32=f32)
   end subroutine grid_displace_single_in_place

   subroutine grid_apply_spectrum(op, which, in, out)
      class(grid_operator), intent(inout) :: op
      integer, intent(in) :: which
      real(dp), intent(in) :: in(:, :)
      real(dp), intent(out) :: out(:, :)
      call gap_transform_apply(op%gaps, which, in, out)
   end subroutine grid_apply_spectrum

   !> Up to how%direct_corrections changes directly from the table; the kernel split takes
   !> up to the budget with the smallest window (one lattice cell), for the full kernel
   !> only (not periodic, not truncated).
   subroutine grid_correction_limits(op, how, limit, split_limit)
      class(grid_operator), intent(in) :: op
      type(cg_settings), intent(in) :: how
      integer, intent(out) :: limit, split_limit
      limit = 0
      split_limit = 0
      ! The corrections read the float32 table: an operator without it convolves afresh.
      if (.not. allocated(op%table)) return
      limit = max(how%direct_corrections, 0)
      if (.not. (op%periodic .or. op%truncated)) split_limit = kernel_split_limit(op%np, how)
   end subroutine grid_correction_limits

   !> How many changed forces the kernel split takes on an NP x NP grid: the budget with
   !> the smallest window (one lattice cell); 0 when how's split is off.
   pure integer function kernel_split_limit(np, how) result(limit)
      integer, intent(in) :: np
      type(cg_settings), intent(in) :: how
      limit = 0
      if (how%split_radius >= how%split_cell .and. how%split_cell >= 1) &
         limit = int(min(how%split_budget*real(np, dp)**2/real(2*how%split_cell + 1, dp)**2, &
         real(np, dp)**2, real(huge(1)/2, dp)))
   end function kernel_split_limit

   !> w += c I * (the changed forces' corrections), summed directly from the table (the
   !> changes sorted by column, then row: the sums in one order).
   subroutine grid_add_direct(op, w, changed, delta, n)
      class(grid_operator), intent(in) :: op
      real(dp), intent(inout) :: w(:, :)
      integer, intent(in) :: changed(:, :)
      real(dp), intent(in) :: delta(:)
      integer, intent(in) :: n
      integer :: jj, ii, q, iq, jq
      !$omp parallel do private(ii, q, iq, jq)
      do jj = 1, op%nj
         do q = 1, n
            iq = changed(1, q)
            jq = changed(2, q)
            do ii = 1, op%np
               w(ii, jj) = w(ii, jj) + op%c*delta(q)*real(op%table(abs(ii - iq), abs(jj - jq)), dp)
            end do
         end do
      end do
   end subroutine grid_add_direct

   !> The kernel split, with the widest window the budget allows, while its error bound
   !> (each change's far error, summed since the last fresh convolution: split_error, nm)
   !> stays within `allowance` (nm); `applied` false when it would not.
   subroutine grid_split_correct(op, w, changed, delta, n, how, allowance, split_error, applied)
      class(grid_operator), intent(inout) :: op
      real(dp), intent(inout) :: w(:, :)
      integer, intent(in) :: changed(:, :)
      real(dp), intent(in) :: delta(:)
      integer, intent(in) :: n
      type(cg_settings), intent(in) :: how
      real(dp), intent(in) :: allowance
      real(dp), intent(inout) :: split_error
      logical, intent(out) :: applied
      call split_within_allowance(op%split, op%np, op%c, w, changed, delta, n, how, allowance, split_error, applied)
   end subroutine grid_split_correct

   !> The kernel split of the n changes (changed: the grid's rows and columns, delta: nN)
   !> on an NP x NP grid of compliance c (nm/nN), with the widest window the budget allows,
   !> applied to w when the error bound since the last fresh convolution (split_error, nm)
   !> stays within `allowance` (nm); `applied` false when it would not. w holds the
   !> grid's columns first_column + 1 .. (split_apply; default all of them).
   subroutine split_within_allowance(split, np, c, w, changed, delta, n, how, allowance, split_error, applied, &
      first_column)
      type(split_correction), intent(inout) :: split
      integer, intent(in) :: np, n
      real(dp), intent(in) :: c
      real(dp), intent(inout) :: w(:, :)
      integer, intent(in) :: changed(:, :)
      real(dp), intent(in) :: delta(:)
      type(cg_settings), intent(in) :: how
      real(dp), intent(in) :: allowance
      real(dp), intent(inout) :: split_error
      logical, intent(out) :: applied
      integer, intent(in), optional :: first_column
      real(dp) :: bound
      integer :: reach
      if (split%np /= np) call split_setup(split, np, how%split_cell, how%split_radius)
      reach = min(how%split_radius, int((sqrt(how%split_budget*real(np, dp)**2/max(n, 1)) - 1)/2))
      reach = max(reach, how%split_cell)
      bound = split_error + c*split%far_error(reach)*sum(abs(delta(1:n)))
      applied = bound <= allowance
      if (.not. applied) return
      split_error = bound
      call split_apply(split, w, c, changed, delta, n, reach, first_column)
   end subroutine split_within_allowance
end module femcod_elastic_operator
