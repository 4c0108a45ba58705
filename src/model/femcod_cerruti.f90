!> The Cerruti kernel: the tangential surface displacements of a half-space under a
!> uniform tangential (shear) traction on one square pixel, in closed form, as the Love
!> kernel (femcod_love) is for a uniform pressure. The thesis' second route to friction
!> (section 5.2.3: "the surface displacement calculation can be extended to include
!> solutions for a surface shear distribution using a Boussinesq-Cerruti solution").
!>
!> A tangential point force Q_x at the origin of a half-space of shear modulus G and
!> Poisson's ratio nu displaces its surface by (Johnson, Contact Mechanics, eq. 2.19;
!> Love 1929)
!>     u_x = Q_x/(2 pi G) [(1 - nu)/rho + nu x^2/rho^3],   u_y = Q_x/(2 pi G) nu x y/rho^3,
!> and normally by -Q_x (1 - 2 nu) x/(4 pi G rho^2), the coupling that femcod leaves out
!> (Goodman's approximation; nothing of it for two bodies of one material, or for
!> incompressible ones: the second Dundurs constant beta is 0).
!>
!> Over a square pixel of side d centred at (x, y) the three integrals have primitives
!> whose second mixed derivative is the integrand (X = x - xi, Y = y - eta, rho^2 = X^2 +
!> Y^2):
!>     int int X^2/rho^3:  Y ln(X + rho)  = Y asinh(X/|Y|) + (a term that cancels)
!>     int int Y^2/rho^3:  X ln(Y + rho)  = X asinh(Y/|X|) + ...
!>     int int X Y/rho^3:  -rho
!> taken at the four corners with signs (+ + , - +, + -, - -) as in eq. 4.4; the sum of the
!> first two is the Love influence. So a uniform shear traction tau_x (GPa) on the pixel
!> at offset (p, q) (p rows, along y; q columns, along x) displaces the pixel at the
!> origin by
!>     u_x = d tau_x/(2 pi G) [I_XX + (1 - nu) I_YY],   u_y = d tau_x/(2 pi G) nu I_XY,
!> and tau_y by u_y = d tau_y/(2 pi G) [I_YY + (1 - nu) I_XX], u_x = d tau_y/(2 pi G) nu I_XY,
!> with the dimensionless integrals I of the unit pixel. x runs along the columns j, y
!> against the rows i (up the page: the axes of PREFIX.xdmf's mesh and of the figures).
module femcod_cerruti
   use femcod_kinds, only: dp
   use femcod_love_periodic, only: periodic_cerruti_spectra
   implicit none
   private
   public :: cerruti_integrals, tangential_tables, tangential_table_column, second_dundurs_constant, &
      periodic_tangential_spectra, periodic_tangential_spectra_rows

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   !> The dimensionless integrals of the unit pixel at offset (p rows, q columns):
   !> w(1) = int int X^2/rho^3, w(2) = int int Y^2/rho^3, w(3) = int int X Y/rho^3 (X along
   !> the columns, Y against the rows: the pixel's centre at x = q, y = -p).
   pure function cerruti_integrals(p, q) result(w)
      integer, intent(in) :: p, q
      real(dp) :: w(3)
      real(dp), parameter :: h = 0.5_dp
      real(dp) :: x, y
      x = q
      y = -p
      w(1) = corners(along_x, x, y)
      w(2) = corners(along_y, x, y)
      w(3) = corners(cross, x, y)
   contains
      pure real(dp) function corners(f, x, y)
         interface
            pure real(dp) function f(a, b)
               import :: dp
               real(dp), intent(in) :: a, b
            end function f
         end interface
         real(dp), intent(in) :: x, y
         corners = f(x + h, y + h) - f(x + h, y - h) - f(x - h, y + h) + f(x - h, y - h)
      end function corners
   end function cerruti_integrals

   !> Y asinh(X/|Y|): the primitive of X^2/rho^3 (0 on Y = 0, its limit).
   pure real(dp) function along_x(a, b)
      real(dp), intent(in) :: a, b
      along_x = 0
      if (b /= 0) along_x = b*asinh(a/abs(b))
   end function along_x

   !> X asinh(Y/|X|): the primitive of Y^2/rho^3.
   pure real(dp) function along_y(a, b)
      real(dp), intent(in) :: a, b
      along_y = 0
      if (a /= 0) along_y = a*asinh(b/abs(a))
   end function along_y

   !> -rho: the primitive of X Y/rho^3.
   pure real(dp) function cross(a, b)
      real(dp), intent(in) :: a, b
      cross = -sqrt(a*a + b*b)
   end function cross

   !> The tangential compliance tables (nm/nN) of the two bodies together, offsets
   !> (p, q) = 0 .. np-1 (rows, columns): a tangential force t (nN) on one pixel moves the
   !> other by u = (xx t_x + xy t_y, xy t_x + yy t_y), the bodies' displacements added
   !> (equal and opposite forces; their relative tangential displacement). Each body:
   !> 1/(2 pi G d) times the pixel integrals (module header), G = E/(2 (1 + nu)). xx and
   !> yy are even in both offsets, xy odd in both (these tables hold p, q >= 0).
   pure subroutine tangential_tables(np, pixel, young, poisson, xx, yy, xy)
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel, young(2), poisson(2)
      real(dp), intent(out) :: xx(0:np - 1, 0:np - 1), yy(0:np - 1, 0:np - 1), xy(0:np - 1, 0:np - 1)
      integer :: q
      do q = 0, np - 1
         call tangential_table_column(np, q, pixel, young, poisson, xx(:, q), yy(:, q), xy(:, q))
      end do
   end subroutine tangential_tables

   !> Column q of tangential_tables: the offsets (p, q), p = 0 .. np-1 (so that a process
   !> holding some columns makes only its own).
   pure subroutine tangential_table_column(np, q, pixel, young, poisson, xx, yy, xy)
      integer, intent(in) :: np, q
      real(dp), intent(in) :: pixel, young(2), poisson(2)
      real(dp), intent(out) :: xx(0:np - 1), yy(0:np - 1), xy(0:np - 1)
      real(dp) :: w(3), c(2)
      integer :: p, b
      do b = 1, 2
         c(b) = (1 + poisson(b))/(pi*young(b)*pixel)
      end do
      do p = 0, np - 1
         w = cerruti_integrals(p, q)
         xx(p) = 0
         yy(p) = 0
         xy(p) = 0
         do b = 1, 2
            xx(p) = xx(p) + c(b)*(w(1) + (1 - poisson(b))*w(2))
            yy(p) = yy(p) + c(b)*(w(2) + (1 - poisson(b))*w(1))
            xy(p) = xy(p) + c(b)*poisson(b)*w(3)
         end do
      end do
   end subroutine tangential_table_column

   !> The periodic cell's tangential compliance spectra (nm/nN; the DFT of the tables of
   !> the kernel summed over all images, zero-mean), in the layout of a 2-D r2c transform
   !> of the NP x NP grid: xx(kp + 1, kq + 1), kp = 0 .. NP/2 the rows' frequency (the
   !> halved one), kq = 0 .. NP-1 the columns' (wrapped). From femcod_love_periodic's
   !> alias sums: with X along the columns and Y up the rows, the xy spectrum is +C(kx)
   !> C(ky) in the rows' frequency kp = -ky (the sign of y = -p; module header).
   subroutine periodic_tangential_spectra(np, pixel, young, poisson, xx, yy, xy)
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel, young(2), poisson(2)
      real(dp), intent(out) :: xx(np/2 + 1, np), yy(np/2 + 1, np), xy(np/2 + 1, np)
      call periodic_tangential_spectra_rows(np, 0, np/2 + 1, pixel, young, poisson, xx, yy, xy)
   end subroutine periodic_tangential_spectra

   !> The rows kp = first .. first + count - 1 of periodic_tangential_spectra:
   !> xx(kp - first + 1, kq + 1) (so that a process holding some of the rows' frequencies,
   !> femcod-mpi's ranks, keeps only its own; each makes the quarter alias sums).
   subroutine periodic_tangential_spectra_rows(np, first, count, pixel, young, poisson, xx, yy, xy)
      integer, intent(in) :: np, first, count
      real(dp), intent(in) :: pixel, young(2), poisson(2)
      real(dp), intent(out) :: xx(count, np), yy(count, np), xy(count, np)
      real(dp), allocatable :: wxx(:, :), wc(:, :)
      real(dp) :: c(2), w1, w2, w3
      integer :: kp, kq, q, b, r
      if (count <= 0) return
      allocate(wxx(0:np/2, 0:np/2), wc(0:np/2, 0:np/2))
      call periodic_cerruti_spectra(np, wxx, wc)
      do b = 1, 2
         c(b) = (1 + poisson(b))/(pi*young(b)*pixel)
      end do
      do kq = 0, np - 1
         q = min(kq, np - kq)
         do r = 1, count
            kp = first + r - 1
            ! wxx(kx, ky): the X^2 integral at column frequency kx, row frequency ky.
            w1 = wxx(q, kp)
            w2 = wxx(kp, q)
            w3 = wc(q, kp)
            if (kq > np/2) w3 = -w3
            xx(r, kq + 1) = 0
            yy(r, kq + 1) = 0
            xy(r, kq + 1) = 0
            do b = 1, 2
               xx(r, kq + 1) = xx(r, kq + 1) + c(b)*(w1 + (1 - poisson(b))*w2)
               yy(r, kq + 1) = yy(r, kq + 1) + c(b)*(w2 + (1 - poisson(b))*w1)
               xy(r, kq + 1) = xy(r, kq + 1) + c(b)*poisson(b)*w3
            end do
         end do
      end do
   end subroutine periodic_tangential_spectra_rows

   !> Dundurs' second constant of two bodies (E GPa, nu): beta = [G1 (1 - 2 nu2) - G2
   !> (1 - 2 nu1)] / [2 G1 (1 - nu2) + 2 G2 (1 - nu1)]: the coupling of normal and
   !> tangential displacements, 0 for one material or incompressible bodies.
   pure real(dp) function second_dundurs_constant(young, poisson) result(beta)
      real(dp), intent(in) :: young(2), poisson(2)
      real(dp) :: g(2)
      g = young/(2*(1 + poisson))
      beta = (g(1)*(1 - 2*poisson(2)) - g(2)*(1 - 2*poisson(1)))/(2*g(1)*(1 - poisson(2)) + 2*g(2)*(1 - poisson(1)))
   end function second_dundurs_constant
end module femcod_cerruti
