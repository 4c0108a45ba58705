!> Love-kernel convolution on the whole NP x NP grid by zero-padded (2NP)^2 real FFTs
!> (FFTW r2c/c2r, plans made once): (I * F)(p) = sum_k I(p - k) F(k), exact for the
!> non-periodic half-space because the padding keeps every image out of the grid.
module femcod_convolution
   use, intrinsic :: iso_c_binding, only: c_ptr, c_double, c_double_complex, c_int, c_size_t, c_f_pointer
   use femcod_kinds, only: dp
   use femcod_fftw, only: fftw_plan_dft_r2c_2d, fftw_plan_dft_c2r_2d, fftw_execute_dft_r2c, fftw_execute_dft_c2r, &
      fftw_destroy_plan, fftw_alloc_real, fftw_alloc_complex, fftw_free, FFTW_ESTIMATE
   implicit none
   private
   public :: love_convolution, convolution_setup, convolution_apply, convolution_free

   !> Plans, the transformed kernel and work arrays for one grid size.
   type :: love_convolution
      integer :: np = 0, m = 0
      type(c_ptr) :: forward, backward, real_mem, complex_mem
      real(c_double), pointer :: work(:, :) => null()
      complex(c_double_complex), pointer :: spectrum(:, :) => null()
      complex(c_double_complex), allocatable :: kernel(:, :)
   end type love_convolution

contains

   !> Plan the transforms and transform the kernel table(0:np-1, 0:np-1).
   subroutine convolution_setup(conv, table)
      type(love_convolution), intent(inout) :: conv
      real(dp), intent(in) :: table(0:, 0:)
      integer :: np, m, p, q, ip, iq
      np = size(table, 1)
      m = 2*np
      conv%np = np
      conv%m = m
      conv%real_mem = fftw_alloc_real(int(m, c_size_t)*int(m, c_size_t))
      conv%complex_mem = fftw_alloc_complex(int(m/2 + 1, c_size_t)*int(m, c_size_t))
      call c_f_pointer(conv%real_mem, conv%work, [m, m])
      call c_f_pointer(conv%complex_mem, conv%spectrum, [m/2 + 1, m])
      conv%forward = fftw_plan_dft_r2c_2d(int(m, c_int), int(m, c_int), conv%work, conv%spectrum, FFTW_ESTIMATE)
      conv%backward = fftw_plan_dft_c2r_2d(int(m, c_int), int(m, c_int), conv%spectrum, conv%work, FFTW_ESTIMATE)
      ! Kernel on the padded grid: offsets 0..np-1 and -(np-1)..-1 (wrapped); the
      ! middle row/column (offset np) is never reached by a pair of grid pixels.
      conv%work = 0
      do q = -(np - 1), np - 1
         iq = modulo(q, m) + 1
         do p = -(np - 1), np - 1
            ip = modulo(p, m) + 1
            conv%work(ip, iq) = table(abs(p), abs(q))
         end do
      end do
      call fftw_execute_dft_r2c(conv%forward, conv%work, conv%spectrum)
      conv%kernel = conv%spectrum/real(m, dp)**2
   end subroutine convolution_setup

   !> result(i, j) = sum_{k,l} I(i-k, j-l) field(k, l) over the NP x NP grid.
   subroutine convolution_apply(conv, field, result)
      type(love_convolution), intent(inout) :: conv
      real(dp), intent(in) :: field(:, :)
      real(dp), intent(out) :: result(:, :)
      integer :: np
      np = conv%np
      conv%work = 0
      conv%work(1:np, 1:np) = field
      call fftw_execute_dft_r2c(conv%forward, conv%work, conv%spectrum)
      conv%spectrum = conv%spectrum*conv%kernel
      call fftw_execute_dft_c2r(conv%backward, conv%spectrum, conv%work)
      result = conv%work(1:np, 1:np)
   end subroutine convolution_apply

   subroutine convolution_free(conv)
      type(love_convolution), intent(inout) :: conv
      if (conv%m == 0) return
      call fftw_destroy_plan(conv%forward)
      call fftw_destroy_plan(conv%backward)
      call fftw_free(conv%real_mem)
      call fftw_free(conv%complex_mem)
      nullify(conv%work, conv%spectrum)
      conv%m = 0
   end subroutine convolution_free
end module femcod_convolution
