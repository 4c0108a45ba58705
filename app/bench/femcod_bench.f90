!> `femcod bench [KIND]`: the benchmarks, one module each in app/bench/. Each prints a table
!> (speed next to error, the whole command timed where a user runs one); they only measure,
!> nothing numerical lives in app/. Without a kind, the thesis table (femcod_bench_thesis).
module femcod_bench
   use femcod_strings, only: string_type
   use femcod_bench_thesis, only: bench_thesis
   use femcod_bench_cg, only: bench_cg
   use femcod_bench_convolution, only: bench_convolution
   use femcod_bench_io, only: bench_io
   use femcod_bench_mpi, only: bench_mpi
   use femcod_bench_periodic, only: bench_periodic
   use femcod_bench_frontier, only: bench_frontier
   use femcod_bench_adhesion, only: bench_adhesion
   use femcod_bench_tangential, only: bench_tangential
   use femcod_bench_refine, only: bench_refine
   implicit none
   private
   public :: bench_command

contains

   !> The benchmark the first argument names, with the rest of the arguments; `code` the
   !> exit code (2 for bad arguments).
   subroutine bench_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      code = 0
      if (size(args) > 0) then
         select case (args(1)%s)
         case ("cg")
            call bench_cg(args(2:), code)
            return
         case ("convolution")
            call bench_convolution(args(2:), code)
            return
         case ("io")
            call bench_io(args(2:), code)
            return
         case ("periodic")
            call bench_periodic(args(2:), code)
            return
         case ("frontier")
            call bench_frontier(args(2:), code)
            return
         case ("adhesion")
            call bench_adhesion(args(2:), code)
            return
         case ("tangential")
            call bench_tangential(args(2:), code)
            return
         case ("mpi")
            call bench_mpi(args(2:), code)
            return
         case ("refine")
            call bench_refine(args(2:), code)
            return
         end select
      end if
      call bench_thesis(args, code)
   end subroutine bench_command
end module femcod_bench
