!> BOUSSINESQ, SPRING, COLHT and TRFACT against analysis and independent calculations.
module test_boussinesq
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_boussinesq, only: boussinesq_flexibility, boussinesq_inverse, boussinesq_element
   use femcod_love, only: love_influence, love_influence_exact, love_influence_far, surface_compliance, &
      offset_table
   use femcod_spring, only: spring_stiffness
   use femcod_skyline, only: colht, diagonal_addresses, assemble_element
   use femcod_trfact, only: trfact, trfact_condition, TRFACT_FACTOR, TRFACT_SOLVE
   use femcod_lapack, only: dgesv, dlacn2
   use femcod_random, only: random_stream, seed_stream, uniform
   use femcod_workspace, only: workspace_type, workspace_layout, allocate_workspace, skyline_words, IPIADR, IPCONT, MPWORK
   use femcod_legacy, only: legacy_unit_solution, legacy_materials
   use femcod_thesis, only: PIXEL_COMPLIANCE, FIG_5_2_PERCENT, FIG_5_2_PERMILLE
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_boussinesq

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   subroutine collect_boussinesq(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("Love self term 4 ln(1+sqrt 2); compliance 5.39e-4 nm/nN (section 4.5)", test_self_term), &
         new_unittest("Fig. 5.2 decay: below 1/100 after 28, below 1/1000 after 283", test_decay), &
         new_unittest("far-field expansion meets the exact sum at 20 pixels", test_far_field), &
         new_unittest("BOUSSINESQ element: eq. 4.6 rigid-body rows, inverse", test_element), &
         new_unittest("SPRING stiffness eq. 4.9", test_spring), &
         new_unittest("COLHT heights by hand and femcod's skyline size", test_colht), &
         new_unittest("TRFACT against a dense LAPACK solve", test_trfact), &
         new_unittest("TRFACT's condition estimate against the exact one and LAPACK's dlacn2", test_condition), &
         new_unittest("legacy unit solution: one and two contacts by hand", test_unit_solution) &
         ]
   end subroutine collect_boussinesq

   subroutine test_self_term(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c
      call check(error, love_influence(0, 0), 4*log(1 + sqrt(2.0_dp)), rel=.true., thr=1.0e-15_dp)
      if (allocated(error)) return
      ! Section 4.5 (femcod_thesis): E = 200 GPa, nu = 0.25, d = 5000/512 nm gives 5.39e-4
      ! nm/nN, printed to three digits.
      c = surface_compliance(200.0_dp, 0.25_dp, 5000.0_dp/512)*love_influence(0, 0)
      call check(error, c, PIXEL_COMPLIANCE, thr=0.005e-4_dp)
   end subroutine test_self_term

   subroutine test_decay(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: i0
      i0 = love_influence(0, 0)
      ! Thesis Fig. 5.2 (femcod_thesis): below 1/100 between pixels 28 and 29, below 1/1000
      ! between 283 and 284.
      associate(n => FIG_5_2_PERCENT, m => FIG_5_2_PERMILLE)
         call check(error, love_influence(n, 0) > i0/100 .and. love_influence(n + 1, 0) < i0/100, "1/100 crossing")
         if (allocated(error)) return
         call check(error, love_influence(m, 0) > i0/1000 .and. love_influence(m + 1, 0) < i0/1000, "1/1000 crossing")
      end associate
   end subroutine test_decay

   subroutine test_far_field(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: p, q
      real(dp) :: e, f
      ! Analysis (the expansion's next term is O(rho**-9)) and a 50-digit evaluation give
      ! agreement to about 1e-14 at rho = 20; allow 1e-12.
      do q = 0, 20
         p = nint(sqrt(max(400.0_dp - q*q, 0.0_dp)))
         e = love_influence_exact(real(p, dp), real(q, dp))
         f = love_influence_far(real(p, dp), real(q, dp))
         call check(error, f, e, rel=.true., thr=1.0e-12_dp, message="offset ("//to_string(p)//","//to_string(q)//")")
         if (allocated(error)) return
      end do
      ! Symmetric in p and q, even in each.
      call check(error, love_influence(3, 7) == love_influence(7, 3) .and. love_influence(-3, 7) == &
         love_influence(3, 7), "symmetry")
   end subroutine test_far_field

   subroutine test_element(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: rows(4) = [1, 1, 2, 5], cols(4) = [1, 2, 2, 4]
      real(dp) :: table(0:5, 0:5), flex(4, 4), kinv(4, 4), element(5, 5), eye(4, 4)
      type(status_type) :: status
      integer :: k
      table = offset_table(6)
      flex = boussinesq_flexibility(rows, cols, table)
      call boussinesq_inverse(flex, kinv, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      eye = 0
      do k = 1, 4
         eye(k, k) = 1
      end do
      call check(error, maxval(abs(matmul(kinv, flex) - eye)) < 1.0e-13_dp, "inverse of the flexibility")
      if (allocated(error)) return
      call boussinesq_element(kinv, 0.01_dp, element)
      ! Eq. 4.6: no force under a rigid-body motion of all nodes and the handle.
      call check(error, maxval(abs(matmul(element, [1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp]))) < &
         1.0e-12_dp*maxval(abs(element)), "rigid-body motion gives no force")
      if (allocated(error)) return
      call check(error, maxval(abs(element - transpose(element))) == 0, "symmetric")
   end subroutine test_element

   subroutine test_spring(error)
      type(error_type), allocatable, intent(out) :: error
      ! Eq. 4.9 by hand: E = 1, nu = 0 gives d**2/h; nu = 0.25 gives E 0.75/(1.25*0.5) d**2/h = 1.2 E d**2/h.
      call check(error, spring_stiffness(1.0_dp, 0.0_dp, 2.0_dp, 4.0_dp), 1.0_dp, thr=1.0e-15_dp)
      if (allocated(error)) return
      call check(error, spring_stiffness(200.0_dp, 0.25_dp, 1.0_dp, 1.0_dp), 240.0_dp, rel=.true., thr=1.0e-15_dp)
   end subroutine test_spring

   subroutine test_colht(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: height(4), iadr(4), n, neq, m
      type(workspace_type) :: ws
      type(status_type) :: status
      real(dp) :: table(0:7, 0:7), delta, f(5)
      ! By hand: elements (1,3), (2,3), (fixed,4): column 3 reaches row 1 (height 2),
      ! the others only their diagonal; addresses 1, 2, 5, 6.
      height = 0
      call colht([1, 3], height)
      call colht([2, 3], height)
      call colht([0, 4], height)
      call check(error, all(height == [0, 0, 2, 0]), "heights")
      if (allocated(error)) return
      call diagonal_addresses(height, iadr)
      call check(error, all(iadr == [1, 2, 5, 6]), "diagonal addresses")
      if (allocated(error)) return
      ! The legacy skyline for n contacts has the size of doc/workspace.md's rule.
      table = offset_table(8)
      do n = 1, 5
         call workspace_layout(8, 5, ws, status)
         call allocate_workspace(ws, status)
         call set_contacts(ws, [(1 + m, m = 1, n)], [(3, m = 1, n)])
         call legacy_unit_solution(ws, n, table, legacy_materials([0.01_dp, 1.0e-7_dp], [1.0e5_dp, 1.0e5_dp], &
            1.0e5_dp), 1.0_dp, delta, status)
         neq = 4*n + 1
         call check(error, ws%ia(ws%ifirst(IPIADR) + neq - 1) == skyline_words(n), "skyline words, n = "// &
            to_string(n))
         if (allocated(error)) return
      end do
   end subroutine test_colht

   subroutine test_trfact(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 30
      integer :: height(n), iadr(n), i, j, ipiv(n), info
      real(dp) :: dense(n, n), b(n), x(n), u
      real(dp), allocatable :: a(:)
      type(random_stream) :: stream
      type(status_type) :: status
      call seed_stream(stream, 3)
      do j = 1, n
         call uniform(stream, u)
         height(j) = min(j - 1, int(u*8))
      end do
      height(n) = n - 1
      call diagonal_addresses(height, iadr)
      allocate(a(iadr(n)))
      dense = 0
      do j = 1, n
         do i = j - height(j), j
            call uniform(stream, u)
            dense(i, j) = u - 0.5_dp
            dense(j, i) = dense(i, j)
         end do
         dense(j, j) = n
      end do
      do j = 1, n
         do i = j - height(j), j
            a(iadr(j) - (j - i)) = dense(i, j)
         end do
         b(j) = real(j, dp)
      end do
      x = b
      call trfact(a, iadr, x, TRFACT_FACTOR, status)
      call trfact(a, iadr, x, TRFACT_SOLVE, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call dgesv(n, 1, dense, n, ipiv, b, n, info)
      call check(error, maxval(abs(x - b)) < 1.0e-13_dp*maxval(abs(b)), "skyline solve equals dense LU")
   end subroutine test_trfact

   !> trfact_condition on random symmetric skyline matrices (n = 2 to 40, diagonally
   !> dominant by a factor 4 down to 1.0001, so from well to ill conditioned): never above the exact ||K||_1 ||K^-1||_1 (the
   !> inverse by a dense LAPACK solve of the identity) and within a factor 3 of it (Higham
   !> 1988: the estimator is usually exact on such matrices), and equal to within 1e-12 to
   !> the same estimator through LAPACK's own dlacn2 (femcod's until it was written in
   !> plain loops; only the order of its sums differs).
   subroutine test_condition(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: trial, n, i, j, info, kase, isave(3), checked
      integer, allocatable :: height(:), iadr(:), ipiv(:), isgn(:)
      real(dp), allocatable :: a(:), factored(:), dense(:, :), inverse(:, :), v(:), x(:)
      real(dp) :: u, exact, lapack, est, diagonal, norm, diagonals(4)
      type(random_stream) :: stream
      type(status_type) :: status
      call seed_stream(stream, 11)
      checked = 0
      do trial = 1, 40
         n = 2 + mod(trial*7, 39)
         diagonals = [4.0_dp, 1.5_dp, 1.01_dp, 1.0001_dp]
         diagonal = diagonals(1 + mod(trial, 4))
         allocate(height(n), iadr(n), ipiv(n), isgn(n), dense(n, n), inverse(n, n), v(n), x(n))
         do j = 1, n
            call uniform(stream, u)
            height(j) = min(j - 1, int(u*8))
         end do
         call diagonal_addresses(height, iadr)
         allocate(a(iadr(n)))
         dense = 0
         do j = 1, n
            do i = j - height(j), j - 1
               call uniform(stream, u)
               dense(i, j) = u - 0.5_dp
               dense(j, i) = dense(i, j)
            end do
         end do
         ! Diagonally dominant by a factor `diagonal` (symmetric: positive definite).
         do j = 1, n
            dense(j, j) = diagonal*sum(abs(dense(:, j))) + 1.0e-3_dp
         end do
         do j = 1, n
            do i = j - height(j), j
               a(iadr(j) - (j - i)) = dense(i, j)
            end do
         end do
         factored = a
         call trfact(factored, iadr, x, TRFACT_FACTOR, status)
         if (status%code /= 0) then
            deallocate(height, iadr, ipiv, isgn, dense, inverse, v, x, a)
            cycle
         end if
         est = trfact_condition(factored, a, iadr)
         inverse = 0
         do i = 1, n
            inverse(i, i) = 1
         end do
         norm = maxval(sum(abs(dense), dim=1))
         call dgesv(n, n, dense, n, ipiv, inverse, n, info)
         exact = norm*maxval(sum(abs(inverse), dim=1))
         ! The same estimator through dlacn2 (reverse communication, solves by TRFACT).
         kase = 0
         lapack = 0
         do
            call dlacn2(n, v, x, isgn, lapack, kase, isave)
            if (kase == 0) exit
            call trfact(factored, iadr, x, TRFACT_SOLVE, status)
         end do
         lapack = norm*lapack
         call check(error, info == 0 .and. est <= exact*(1 + 1.0e-10_dp) .and. est >= exact/3, "n = "// &
            to_string(n)//": estimate "//to_string(est)//" against the exact "//to_string(exact))
         if (allocated(error)) return
         call check(error, abs(est - lapack) <= 1.0e-12_dp*est, "n = "//to_string(n)//": estimate "// &
            to_string(est)//" against dlacn2's "//to_string(lapack))
         if (allocated(error)) return
         deallocate(height, iadr, ipiv, isgn, dense, inverse, v, x, a)
         checked = checked + 1
      end do
      call check(error, checked == 40, "only "//to_string(checked)//" of 40 matrices were factored")
   end subroutine test_condition

   subroutine test_unit_solution(error)
      type(error_type), allocatable, intent(out) :: error
      type(workspace_type) :: ws
      type(status_type) :: status
      real(dp) :: table(0:3, 0:3), c1, c2, k, delta, f(2)
      table = offset_table(4)
      c1 = surface_compliance(200.0_dp, 0.25_dp, 1.0_dp)
      c2 = surface_compliance(2.0e7_dp, 0.25_dp, 1.0_dp)
      k = spring_stiffness(2.0e7_dp, 0.25_dp, 1.0_dp, 1.0_dp)
      call workspace_layout(4, 2, ws, status)
      call allocate_workspace(ws, status)
      ! One contact: the two half-spaces and three springs in series.
      call set_contacts(ws, [2], [2])
      call legacy_unit_solution(ws, 1, table, legacy_materials([c1, c2], [k, k], k), 1.0_dp, delta, status)
      f(1) = ws%ra(ws%rfirst(MPWORK))
      call check(error, delta, (c1 + c2)*4*log(1 + sqrt(2.0_dp)) + 3/k, rel=.true., thr=1.0e-9_dp)
      if (allocated(error)) return
      call check(error, f(1), 1.0_dp, rel=.true., thr=1.0e-9_dp)
      if (allocated(error)) return
      ! Two neighbours: by symmetry 0.5 nN each, approach (c1+c2)(I00 + I01)/2 + 3/(2k).
      call set_contacts(ws, [2, 2], [2, 3])
      call legacy_unit_solution(ws, 2, table, legacy_materials([c1, c2], [k, k], k), 1.0_dp, delta, status)
      f = ws%ra(ws%rfirst(MPWORK):ws%rfirst(MPWORK) + 1)
      call check(error, delta, (c1 + c2)*(love_influence(0, 0) + love_influence(0, 1))/2 + 1.5_dp/k, rel=.true., &
         thr=1.0e-9_dp)
      if (allocated(error)) return
      call check(error, f(1), 0.5_dp, rel=.true., thr=1.0e-9_dp)
   end subroutine test_unit_solution

   !> Contacts at rows `i`, columns `j` into IPCONT, as the legacy solver keeps them.
   subroutine set_contacts(ws, i, j)
      type(workspace_type), intent(inout) :: ws
      integer, intent(in) :: i(:), j(:)
      ws%ia(ws%ifirst(IPCONT):ws%ifirst(IPCONT) + size(i) - 1) = (i - 1)*ws%np + j
   end subroutine set_contacts
end module test_boussinesq
