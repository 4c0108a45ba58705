!> The displacements of a scattered set of force changes, c sum_q d_q I(x - x_q) at every
!> pixel of an NP x NP grid, for far less than a full convolution when the changes are
!> few, by splitting the Love kernel as particle-mesh codes split the Coulomb kernel
!> (Hockney and Eastwood, "Computer simulation using particles", 1988, ch. 8):
!> - far: each change is assigned to the four nodes around it of a lattice of spacing
!>   k pixels (bilinear weights), the node loads are convolved with the kernel sampled at
!>   the nodes, I(k a, k b), by a zero-padded FFT on the ((NP-1)/k + 2)^2 nodes (1/k^2 of
!>   the grid), and the result is interpolated bilinearly back to every pixel. Call this
!>   A(x, x_q): a smooth approximation of I(x - x_q), accurate when |x - x_q| >> k.
!> - near: within a window of R pixels around each change the difference I - A is added
!>   from a table, so that there the sum is exact (to float32 rounding of the table).
!>   A depends on x_q only through x_q's offset in its lattice cell, so one table
!>   D(dx, dy, sx, sy) = I(dx, dy) - A(x_q + (dx, dy), x_q), x_q = (sx, sy), serves all
!>   changes ((2R + 1)^2 k^2 entries; 1 MB in float32 for R = 32, k = 8).
!> Beyond the window the error is that of A, of relative order (k/r)^2 at r pixels; its
!> largest value outside a window of R pixels, far_error(R), is tabulated at set-up
!> (test_split_correction in test/test_cg.f90 checks the bound against the direct sum).
!> The fixed-load solver (femcod_cg) adds the projection's changes this way when they
!> are too many for a direct sum from the Love table, instead of a fresh convolution, as
!> long as the error bound stays below its residual. The non-periodic kernel only.
!> Cost at NP = 4096, k = 8: the node convolution and the interpolation to every pixel
!> (about 0.015 s), plus (2R + 1)^2 multiply-adds per change; at R = 32, 0.023 s in all
!> for 10000 changes and 0.052 s for 50000, against 0.22 s for a float32 (8192)^2
!> convolution.
module femcod_split_correction
   use femcod_kinds, only: dp, sp
   use femcod_love, only: love_influence
   use femcod_convolution, only: love_convolution, convolution_setup, convolution_apply, convolution_free
   implicit none
   private
   public :: split_correction, split_setup, split_apply, split_free, split_hand_over

   !> The lattice, the near table and the node convolution for one grid size.
   type :: split_correction
      !> Grid side NP (pixels; 0: no mesh), lattice spacing k (pixels), largest window R
      !> (pixels), nodes per side nn = (NP - 1)/k + 2 (node a at pixel coordinate k a,
      !> a = 0 .. nn - 1).
      integer :: np = 0, k = 0, radius = 0, nn = 0
      !> near(dx, dy, sx, sy) = I(dx, dy) - A (dimensionless, as the Love table).
      real(sp), allocatable :: near(:, :, :, :)
      type(love_convolution) :: conv
      !> Node loads and their convolution (nn x nn).
      real(dp), allocatable :: load(:, :), field(:, :)
      !> far_error(R): the largest |I - A| outside a window of R pixels, over all cell
      !> offsets (dimensionless): the error of one unit change's displacement beyond R.
      real(dp), allocatable :: far_error(:)
   end type split_correction

contains

   !> Ready for an NP x NP grid with lattice spacing k and windows of up to `radius`
   !> pixels (radius >= k >= 1): the node mesh for NP, and the tables unless they are
   !> there for the same k and radius already (handed over by split_hand_over).
   subroutine split_setup(split, np, k, radius)
      type(split_correction), intent(inout) :: split
      integer, intent(in) :: np, k, radius
      real(dp), allocatable :: table(:, :)
      integer :: nn, ia, ib
      if (.not. (allocated(split%near) .and. split%k == k .and. split%radius == radius)) then
         call split_free(split)
         call make_tables(split, k, radius)
      end if
      call free_mesh(split)
      nn = (np - 1)/k + 2
      split%np = np
      split%nn = nn
      allocate(table(0:nn - 1, 0:nn - 1), split%load(nn, nn), split%field(nn, nn))
      !$omp parallel do private(ia)
      do ib = 0, nn - 1
         do ia = 0, nn - 1
            table(ia, ib) = love_influence(k*ia, k*ib)
         end do
      end do
      call convolution_setup(split%conv, table)
   end subroutine split_setup

   !> The near table and far_error for lattice k and windows up to `radius`; they do
   !> not depend on NP (about 5 ms here for k = 8, R = 32).
   subroutine make_tables(split, k, radius)
      type(split_correction), intent(inout) :: split
      integer, intent(in) :: k, radius
      real(dp), allocatable :: lattice(:, :), exact(:, :), ring(:)
      real(dp) :: ux(-1:1), uy(-1:1), a, e
      integer :: c0, d0, sx, sy, dx, dy, mx, my, outer, nl, rho
      split%k = k
      split%radius = radius
      ! The error is recorded out to 2 R + 1 pixels (it falls off as (k/r)^2 I(r)
      ! beyond): the kernel at the pixels and at the nodes within reach.
      outer = 2*radius + 1
      nl = outer/k + 2
      allocate(lattice(-nl:nl, -nl:nl), exact(0:outer, 0:outer), ring(0:outer))
      do dy = -nl, nl
         do dx = -nl, nl
            lattice(dx, dy) = love_influence(k*dx, k*dy)
         end do
      end do
      do dy = 0, outer
         do dx = 0, outer
            exact(dx, dy) = love_influence(dx, dy)
         end do
      end do
      allocate(split%near(-radius:radius, -radius:radius, 0:k - 1, 0:k - 1))
      ! A(x, x_q) = sum over the nodes n around x and m around x_q of phi_n(x) phi_m(x_q)
      ! I(k (n - m)); x_q = (sx, sy) in cell (0, 0), x = x_q + (dx, dy) in cell (c0, d0).
      ! Along x the weight of the node offset n - m = c0 + mx is ux(mx), the sum of
      ! phi_n(x) phi_m(x_q) over the pairs with that offset (likewise along y).
      ring = 0
      !$omp parallel do collapse(2) private(sx, dx, dy, ux, uy, c0, d0, a, e, mx, my, rho) reduction(max:ring)
      do sy = 0, k - 1
         do sx = 0, k - 1
            do dy = -outer, outer
               call offset_weights(sy, dy, k, d0, uy)
               do dx = -outer, outer
                  call offset_weights(sx, dx, k, c0, ux)
                  a = 0
                  do my = -1, 1
                     do mx = -1, 1
                        a = a + ux(mx)*uy(my)*lattice(c0 + mx, d0 + my)
                     end do
                  end do
                  e = exact(abs(dx), abs(dy)) - a
                  rho = max(abs(dx), abs(dy))
                  ring(rho) = max(ring(rho), abs(e))
                  if (rho <= radius) split%near(dx, dy, sx, sy) = real(e, sp)
               end do
            end do
         end do
      end do
      ! far_error(R) = the largest |I - A| at R < max(|dx|, |dy|) <= 2 R_max + 1.
      allocate(split%far_error(0:radius))
      do rho = radius, 0, -1
         split%far_error(rho) = maxval(ring(rho + 1:))
      end do
   end subroutine make_tables

   !> Along one axis, a source at s (0 <= s < k, in cell 0) and a target at s + d in
   !> cell c0: the weight u(m) of node offset c0 + m, m = -1, 0, 1, summed over the
   !> bilinear weights of the source's nodes (0, 1) and the target's (c0, c0 + 1).
   pure subroutine offset_weights(s, d, k, c0, u)
      integer, intent(in) :: s, d, k
      integer, intent(out) :: c0
      real(dp), intent(out) :: u(-1:1)
      real(dp) :: w0, w1, v0, v1
      c0 = floor(real(s + d, dp)/k)
      w0 = real(k - s, dp)/k
      w1 = real(s, dp)/k
      v0 = real(k*(c0 + 1) - (s + d), dp)/k
      v1 = real(s + d - k*c0, dp)/k
      ! Target node c0 + ic, source node ia: offset c0 + ic - ia.
      u(-1) = v0*w1
      u(0) = v0*w0 + v1*w1
      u(1) = v1*w0
   end subroutine offset_weights

   !> Hand the tables (which do not depend on NP) from one grid's split to another's,
   !> when the other has none: the nested grids compute them once.
   subroutine split_hand_over(from, to)
      type(split_correction), intent(inout) :: from, to
      if (.not. allocated(from%near) .or. allocated(to%near)) return
      to%k = from%k
      to%radius = from%radius
      call move_alloc(from%near, to%near)
      call move_alloc(from%far_error, to%far_error)
   end subroutine split_hand_over

   !> w(x) += c sum_q delta(q) A(x, x_q) at every pixel, plus c delta(q) (I - A)(x - x_q)
   !> within `radius` pixels (max(|dx|, |dy|) <= radius <= the set-up's) of each change:
   !> the displacements (nm) of the force changes delta (nN) at the pixels x_q =
   !> (changed(1, q), changed(2, q)), q = 1 .. n, with c the compliance (nm/nN). The changes
   !> come sorted by column, then row (every pixel's sum is then taken in one order, the
   !> answer the same for any number of threads). Beyond the window each change's error
   !> is at most |c delta(q)| far_error(radius). With `first_column` (0-based), w holds
   !> only the grid's columns first_column + 1 .. first_column + size(w, 2) (a rank's
   !> slab; the changes are given in the grid's columns, all of them).
   subroutine split_apply(split, w, c, changed, delta, n, radius, first_column)
      type(split_correction), intent(inout) :: split
      real(dp), intent(inout) :: w(:, :)
      real(dp), intent(in) :: c
      integer, intent(in) :: changed(:, :)
      real(dp), intent(in) :: delta(:)
      integer, intent(in) :: n, radius
      integer, intent(in), optional :: first_column
      integer, allocatable :: first(:)
      real(dp), allocatable :: col(:)
      integer :: k, np, q, i, j, jj, j0, a0, b0, sx, sy, ii, iq, jq, rad
      real(dp) :: fx, fy, d
      k = split%k
      np = split%np
      rad = min(radius, split%radius)
      j0 = 0
      if (present(first_column)) j0 = first_column
      ! Far: the changes assigned to the nodes, the nodes convolved.
      split%load = 0
      do q = 1, n
         a0 = (changed(1, q) - 1)/k
         b0 = (changed(2, q) - 1)/k
         fx = real(changed(1, q) - 1 - k*a0, dp)/k
         fy = real(changed(2, q) - 1 - k*b0, dp)/k
         d = delta(q)
         split%load(a0 + 1, b0 + 1) = split%load(a0 + 1, b0 + 1) + (1 - fx)*(1 - fy)*d
         split%load(a0 + 2, b0 + 1) = split%load(a0 + 2, b0 + 1) + fx*(1 - fy)*d
         split%load(a0 + 1, b0 + 2) = split%load(a0 + 1, b0 + 2) + (1 - fx)*fy*d
         split%load(a0 + 2, b0 + 2) = split%load(a0 + 2, b0 + 2) + fx*fy*d
      end do
      call convolution_apply(split%conv, split%load, split%field, c)
      ! first(j): the first change in column j or after it.
      allocate(first(np + 1))
      first = n + 1
      do q = n, 1, -1
         first(changed(2, q)) = q
      end do
      do j = np, 1, -1
         first(j) = min(first(j), first(j + 1))
      end do
      ! Each column: the nodes interpolated (along the column's two node columns first,
      ! then down the column cell by cell: no division per pixel), then the near part of
      ! the changes within `rad` columns.
      !$omp parallel private(col, j, i, a0, b0, fx, fy, q, iq, jq, sx, sy, d, ii)
      allocate(col(split%nn))
      !$omp do schedule(static)
      do jj = 1, size(w, 2)
         j = j0 + jj
         b0 = (j - 1)/k
         fy = real(j - 1 - k*b0, dp)/k
         col = (1 - fy)*split%field(:, b0 + 1) + fy*split%field(:, b0 + 2)
         do a0 = 0, (np - 1)/k
            do i = a0*k + 1, min(a0*k + k, np)
               fx = real(i - 1 - a0*k, dp)/k
               w(i, jj) = w(i, jj) + ((1 - fx)*col(a0 + 1) + fx*col(a0 + 2))
            end do
         end do
         do q = first(max(j - rad, 1)), first(min(j + rad, np) + 1) - 1
            iq = changed(1, q)
            jq = changed(2, q)
            sx = mod(iq - 1, k)
            sy = mod(jq - 1, k)
            d = c*delta(q)
            do ii = max(iq - rad, 1), min(iq + rad, np)
               w(ii, jj) = w(ii, jj) + d*real(split%near(ii - iq, j - jq, sx, sy), dp)
            end do
         end do
      end do
      !$omp end do
      deallocate(col)
      !$omp end parallel
   end subroutine split_apply

   !> Everything: the tables and the mesh.
   subroutine split_free(split)
      type(split_correction), intent(inout) :: split
      call free_mesh(split)
      if (allocated(split%near)) deallocate(split%near)
      if (allocated(split%far_error)) deallocate(split%far_error)
      split%k = 0
      split%radius = 0
   end subroutine split_free

   !> The node mesh of one NP only.
   subroutine free_mesh(split)
      type(split_correction), intent(inout) :: split
      if (split%np == 0) return
      call convolution_free(split%conv)
      deallocate(split%load, split%field)
      split%np = 0
      split%nn = 0
   end subroutine free_mesh
end module femcod_split_correction
