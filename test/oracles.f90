!> Independent calculations the tests compare femcod with. Nothing here calls the code
!> under test: the Love coefficients are the four-corner sum of eq. 4.4 evaluated in
!> quadruple precision (no far-field switch), the compliances and springs are the
!> closed forms of eqs. 4.4 and 4.9 written out again, the exact state of a contact set
!> is a dense LU solve (LAPACK dgesv, where femcod uses Cholesky factors, dsysv and
!> skyline TRFACT), and the Appendix B stiffness is assembled densely from the thesis'
!> description (section 4.2, Appendix B) for its exact condition number.
module oracles
   use, intrinsic :: iso_fortran_env, only: real128
   use femcod_kinds, only: dp
   use femcod_problem, only: contact_problem
   implicit none
   private
   public :: love_quad, love_table, composite_compliance, spring_compliance, reference_gaps, exact_state, &
      gaps_at_state, appendix_b_condition, first_touch_gaps, grid_stiffness, event_path

   real(dp), parameter :: pi = acos(-1.0_dp)

   interface
      subroutine dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
         import :: dp
         integer, intent(in) :: n, nrhs, lda, ldb
         real(dp), intent(inout) :: a(lda, *), b(ldb, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine dgesv
      subroutine dgetrf(m, n, a, lda, ipiv, info)
         import :: dp
         integer, intent(in) :: m, n, lda
         real(dp), intent(inout) :: a(lda, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine dgetrf
      subroutine dgetri(n, a, lda, ipiv, work, lwork, info)
         import :: dp
         integer, intent(in) :: n, lda, lwork
         real(dp), intent(inout) :: a(lda, *), work(*)
         integer, intent(in) :: ipiv(*)
         integer, intent(out) :: info
      end subroutine dgetri
   end interface

contains

   !> Eq. 4.4's four-corner sum at pixel offset (x, y) in quadruple precision (33
   !> digits: the cancellation at 1000 pixels costs about 6, leaving the value exact to
   !> double precision).
   pure real(real128) function love_quad(x, y)
      real(real128), intent(in) :: x, y
      real(real128), parameter :: h = 0.5_real128
      love_quad = f(x + h, y + h) - f(x + h, y - h) - f(x - h, y + h) + f(x - h, y - h)
   contains
      pure real(real128) function f(a, b)
         real(real128), intent(in) :: a, b
         f = 0
         if (a /= 0) f = f + a*asinh(b/abs(a))
         if (b /= 0) f = f + b*asinh(a/abs(b))
      end function f
   end function love_quad

   !> The dimensionless Love coefficients I(p, q), p, q = 0 .. np-1, from love_quad.
   function love_table(np) result(table)
      integer, intent(in) :: np
      real(dp) :: table(0:np - 1, 0:np - 1)
      integer :: p, q
      do q = 0, np - 1
         do p = 0, np - 1
            table(p, q) = real(love_quad(real(p, real128), real(q, real128)), dp)
         end do
      end do
   end function love_table

   !> c = sum over both bodies of (1 - nu^2)/(pi E d) (nm/nN): eq. 4.4's factor.
   pure real(dp) function composite_compliance(problem)
      type(contact_problem), intent(in) :: problem
      composite_compliance = (1 - problem%poisson(1)**2)/(pi*problem%young(1)*problem%pixel) + &
         (1 - problem%poisson(2)**2)/(pi*problem%young(2)*problem%pixel)
   end function composite_compliance

   !> Compliance of one axial voxel spring of the contact material, eq. 4.9 with h = d:
   !> 1/k, k = E (1 - nu)/((1 + nu)(1 - 2 nu)) d (nm/nN).
   pure real(dp) function spring_compliance(problem)
      type(contact_problem), intent(in) :: problem
      spring_compliance = (1 + problem%poisson(3))*(1 - 2*problem%poisson(3))/ &
         (problem%young(3)*(1 - problem%poisson(3))*problem%pixel)
   end function spring_compliance

   !> The initial gaps g(i, j) = max(hl + hu') - (hl + hu')(i, j), hu' the upper surface
   !> flipped about the horizontal axis (Fig. B.1), as a map (nm).
   pure function reference_gaps(problem) result(g)
      type(contact_problem), intent(in) :: problem
      real(dp) :: g(problem%np, problem%np)
      integer :: i
      do i = 1, problem%np
         g(i, :) = problem%lower(i, :) + problem%upper(problem%np + 1 - i, :)
      end do
      g = maxval(g) - g
   end function reference_gaps

   !> The pixels whose initial gap is within `tolerance` of the smallest (nm).
   pure integer function first_touch_gaps(problem, tolerance)
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: tolerance
      real(dp) :: g(problem%np, problem%np)
      g = reference_gaps(problem)
      first_touch_gaps = count(g <= minval(g) + tolerance)
   end function first_touch_gaps

   !> The exact forces F (nN) and approach A (nm) of the contact set (rows i, columns j)
   !> at total load P: every contact closed, c sum_l I(k - l) F_l + s F_k - A = -g0_k,
   !> sum F = P (s = 3/k: two interface springs and the penalty spring in series), by a
   !> dense LU solve. `table` holds the Love coefficients (love_table).
   subroutine exact_state(problem, table, i, j, load, forces, approach, info)
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: table(0:, 0:), load
      integer, intent(in) :: i(:), j(:)
      real(dp), intent(out) :: forces(:), approach
      integer, intent(out) :: info
      real(dp), allocatable :: a(:, :), b(:, :), g(:, :)
      integer, allocatable :: ipiv(:)
      real(dp) :: c, s
      integer :: n, k, l
      n = size(i)
      c = composite_compliance(problem)
      s = 3*spring_compliance(problem)
      g = reference_gaps(problem)
      allocate(a(n + 1, n + 1), b(n + 1, 1), ipiv(n + 1))
      do l = 1, n
         do k = 1, n
            a(k, l) = c*table(abs(i(k) - i(l)), abs(j(k) - j(l)))
         end do
         a(l, l) = a(l, l) + s
         a(l, n + 1) = -1
         a(n + 1, l) = 1
         b(l, 1) = -g(i(l), j(l))
      end do
      a(n + 1, n + 1) = 0
      b(n + 1, 1) = load
      call dgesv(n + 1, 1, a, n + 1, ipiv, b, n + 1, info)
      forces = b(1:n, 1)
      approach = b(n + 1, 1)
   end subroutine exact_state

   !> The gap (nm) of every pixel under the contact forces F at (i, j) and the approach A:
   !> g0 - A + c sum_k I(p - k) F_k, by the direct sum (contacts included).
   function gaps_at_state(problem, table, i, j, forces, approach) result(gap)
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: table(0:, 0:), forces(:), approach
      integer, intent(in) :: i(:), j(:)
      real(dp) :: gap(problem%np, problem%np)
      real(dp) :: c, sum_if
      integer :: p, q, k
      c = composite_compliance(problem)
      gap = reference_gaps(problem)
      do q = 1, problem%np
         do p = 1, problem%np
            sum_if = 0
            do k = 1, size(forces)
               sum_if = sum_if + table(abs(p - i(k)), abs(q - j(k)))*forces(k)
            end do
            gap(p, q) = gap(p, q) - approach + c*sum_if
         end do
      end do
   end function gaps_at_state

   !> The event path of the elastic contact by brute force, independent of femcod's
   !> solvers: from the pixels that touch first (initial gap within `tie` nm of the
   !> smallest), the contact set's state is linear in the load between events, so two
   !> dense solves (exact_state at loads 0 and 1) give every gap as g(P) = g_0 + P g_1;
   !> the next event is the smallest load above the last at which a pixel off the set
   !> closes (with every pixel that closes within `tie` relative of it), and it joins.
   !> Returned per event: the load (nN) and the contacts carrying it until then; at most
   !> `max_events`, none past `max_load` (nN), the last with MAXCONT contacts. `tie` is
   !> the first touch's tolerance (nm) and a tie's between closing loads (relative). `released` is true when a contact's
   !> force turned tensile before the last event (the path then needs releases, which
   !> this oracle does not follow; the caller compares the events before it only).
   subroutine event_path(problem, table, tie, max_events, max_load, loads, counts, nevents, released, set_i, set_j, &
         hardness, above)
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: table(0:, 0:), tie, max_load
      integer, intent(in) :: max_events
      real(dp), intent(out) :: loads(:)
      integer, intent(out) :: counts(:), nevents
      logical, intent(out) :: released
      !> The contact set (rows, columns) the path stopped with: the set that carries
      !> `max_load` when the path ended there.
      integer, allocatable, intent(out), optional :: set_i(:), set_j(:)
      !> With `hardness` (GPa): per event, the contacts whose pressure at the event's load
      !> is above it.
      real(dp), intent(in), optional :: hardness
      integer, intent(out), optional :: above(:)
      integer, allocatable :: i(:), j(:)
      real(dp), allocatable :: f0(:), f1(:), g0(:, :), g1(:, :)
      real(dp) :: a0, a1, last, next, rate
      logical :: in_set(problem%np, problem%np)
      integer :: p, q, info, np
      np = problem%np
      g0 = reference_gaps(problem)
      in_set = g0 <= minval(g0) + tie
      nevents = 0
      released = .false.
      last = 0
      do while (nevents < max_events)
         i = [integer :: ]
         j = [integer :: ]
         do q = 1, np
            do p = 1, np
               if (in_set(p, q)) then
                  i = [i, p]
                  j = [j, q]
               end if
            end do
         end do
         if (size(i) > problem%maxcont .or. size(i) == np*np) exit
         allocate(f0(size(i)), f1(size(i)))
         call exact_state(problem, table, i, j, 0.0_dp, f0, a0, info)
         if (info /= 0) exit
         call exact_state(problem, table, i, j, 1.0_dp, f1, a1, info)
         if (info /= 0) exit
         g0 = gaps_at_state(problem, table, i, j, f0, a0)
         g1 = gaps_at_state(problem, table, i, j, f1, a1) - g0
         f1 = f1 - f0
         ! The next closing load: g0 + P g1 = 0 for a pixel off the set whose gap falls.
         next = huge(1.0_dp)
         do q = 1, np
            do p = 1, np
               rate = g1(p, q)
               if (.not. in_set(p, q) .and. rate < 0) next = min(next, max(-g0(p, q)/rate, last))
            end do
         end do
         if (next > max_load) exit
         if (any(f0 + next*f1 < -tie*abs(next))) released = .true.
         nevents = nevents + 1
         loads(nevents) = next
         counts(nevents) = size(i)
         if (present(hardness) .and. present(above)) &
            above(nevents) = count((f0 + next*f1)/problem%pixel**2 > hardness)
         last = next
         do q = 1, np
            do p = 1, np
               if (.not. in_set(p, q) .and. g1(p, q) < 0) then
                  if (g0(p, q) + next*g1(p, q) <= tie*max(abs(g0(p, q)), abs(next*g1(p, q)))) in_set(p, q) = .true.
               end if
            end do
         end do
         deallocate(f0, f1)
         ! MAXCONT contacts carry up to the load where one more would close: the last event.
         if (released .or. size(i) == problem%maxcont) exit
      end do
      if (present(set_i)) set_i = pack(spread([(p, p = 1, np)], 2, np), in_set)
      if (present(set_j)) set_j = pack(spread([(q, q = 1, np)], 1, np), in_set)
   end subroutine event_path

   !> The exact 1-norm condition number ||K||_1 ||K^-1||_1 of the Appendix B stiffness
   !> for the contacts (i, j): per contact a lower substrate, a lower and an upper surface
   !> node and an upper substrate node, plus the top handle (the bottom one fixed); the
   !> two Boussinesq elements (the inverse of c_b F, F the Love flexibility of the
   !> contacts, bordered by the handle so that rigid-body motion is force-free, eq. 4.6),
   !> an interface spring on each side and a penalty spring per contact (eq. 4.9),
   !> assembled densely. By LU (dgetrf) and the explicit inverse (dgetri).
   function appendix_b_condition(problem, table, i, j) result(kappa)
      type(contact_problem), intent(in) :: problem
      real(dp), intent(in) :: table(0:, 0:)
      integer, intent(in) :: i(:), j(:)
      real(dp) :: kappa
      real(dp), allocatable :: k(:, :), flex(:, :), kinv(:, :), work(:)
      integer, allocatable :: ipiv(:)
      real(dp) :: cb(2), ks, norm_k
      integer :: n, m, a, b, info, top, body
      n = size(i)
      m = 4*n + 1
      top = m
      cb = [(1 - problem%poisson(1)**2)/(pi*problem%young(1)*problem%pixel), &
         (1 - problem%poisson(2)**2)/(pi*problem%young(2)*problem%pixel)]
      ks = 1/spring_compliance(problem)
      allocate(k(m, m), flex(n, n), ipiv(max(m, n)), work(64*m))
      do b = 1, n
         do a = 1, n
            flex(a, b) = table(abs(i(a) - i(b)), abs(j(a) - j(b)))
         end do
      end do
      kinv = flex
      call dgetrf(n, n, kinv, n, ipiv, info)
      call dgetri(n, kinv, n, ipiv, work, size(work), info)
      k = 0
      ! Unknowns: lower substrate 1..n, lower surface n+1..2n, upper surface 2n+1..3n,
      ! upper substrate 3n+1..4n, top handle 4n+1.
      do body = 1, 2
         associate(off => merge(0, 3*n, body == 1))
            k(off + 1:off + n, off + 1:off + n) = k(off + 1:off + n, off + 1:off + n) + kinv/cb(body)
            if (body == 2) then
               do a = 1, n
                  k(off + a, top) = k(off + a, top) - sum(kinv(a, :))/cb(body)
                  k(top, off + a) = k(off + a, top)
               end do
               k(top, top) = k(top, top) + sum(kinv)/cb(body)
            end if
         end associate
      end do
      do a = 1, n
         call spring(a, n + a)
         call spring(2*n + a, 3*n + a)
         call spring(n + a, 2*n + a)
      end do
      norm_k = maxval(sum(abs(k), dim=1))
      call dgetrf(m, m, k, m, ipiv, info)
      call dgetri(m, k, m, ipiv, work, size(work), info)
      kappa = norm_k*maxval(sum(abs(k), dim=1))
   contains
      subroutine spring(p, q)
         integer, intent(in) :: p, q
         k(p, p) = k(p, p) + ks
         k(q, q) = k(q, q) + ks
         k(p, q) = k(p, q) - ks
         k(q, p) = k(q, p) - ks
      end subroutine spring
   end function appendix_b_condition

   !> The dense stiffness of a whole np x np grid, the inverse of the compliance matrix
   !> C(a, b) = I(|i_a - i_b|, |j_a - j_b|) + spring on the diagonal (dimensionless,
   !> in units of the pixel's Love factor; I from love_table), pixels in column order.
   !> By LU (dgetrf) and the explicit inverse (dgetri).
   function grid_stiffness(np, spring) result(s)
      integer, intent(in) :: np
      real(dp), intent(in) :: spring
      real(dp), allocatable :: s(:, :), table(:, :), work(:)
      integer, allocatable :: ipiv(:)
      integer :: a, b, n, info
      n = np*np
      allocate(table(0:np - 1, 0:np - 1), s(n, n), ipiv(n), work(64*n))
      table(:, :) = love_table(np)
      do b = 1, n
         do a = 1, n
            s(a, b) = table(abs(mod(a - 1, np) - mod(b - 1, np)), abs((a - 1)/np - (b - 1)/np))
         end do
         s(b, b) = s(b, b) + spring
      end do
      call dgetrf(n, n, s, n, ipiv, info)
      call dgetri(n, s, n, ipiv, work, size(work), info)
   end function grid_stiffness
end module oracles
