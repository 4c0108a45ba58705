!> femcod-mpi's test driver: every rank runs every test (the tests are collective); rank 0
!> reports. Run under mpirun: `bash mpi/test.sh` runs it on 1, 2 and 4 ranks.
program mpi_tester
   use, intrinsic :: iso_fortran_env, only: output_unit
   use, intrinsic :: iso_c_binding, only: c_int
   use mpi_f08
   use omp_lib, only: omp_get_max_threads
   use femcod_fftw_mpi, only: fftw_init_threads, fftw_plan_with_nthreads, fftw_mpi_init, fftwf_init_threads, &
      fftwf_plan_with_nthreads, fftwf_mpi_init
   use testdrive, only: run_testsuite, count_tests
   use test_distributed, only: collect_distributed
   use femcod_exit, only: exit_program
   use femcod_strings, only: int_str
   implicit none
   integer :: provided, rank, ranks, unit, stat, failed, total
   call MPI_Init_thread(MPI_THREAD_FUNNELED, provided)
   call MPI_Comm_rank(MPI_COMM_WORLD, rank)
   call MPI_Comm_size(MPI_COMM_WORLD, ranks)
   if (fftw_init_threads() == 0) error stop "FFTW's threads would not start"
   call fftw_mpi_init()
   if (fftwf_init_threads() == 0) error stop "FFTW's float32 threads would not start"
   call fftwf_mpi_init()
   call fftw_plan_with_nthreads(int(omp_get_max_threads(), c_int))
   call fftwf_plan_with_nthreads(int(omp_get_max_threads(), c_int))
   if (rank == 0) then
      unit = output_unit
      write(unit, '(a)') "# suite distributed ("//int_str(ranks)//" MPI ranks)"
   else
      open(newunit=unit, file="/dev/null", action="write")
   end if
   stat = 0
   call run_testsuite(collect_distributed, unit, stat)
   ! A test failed on any rank is failed.
   failed = stat
   call MPI_Allreduce(stat, failed, 1, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD)
   total = count_tests(collect_distributed)
   if (rank == 0) write(unit, '(a)') int_str(total - failed)//" passed, "//int_str(failed)//" failed, 0 skipped"
   call MPI_Finalize()
   call exit_program(merge(1, 0, failed > 0))
end program mpi_tester
