!> The femcod command: `femcod <command> [options]`. Everything numerical lives in
!> src/; this program parses the command line and turns a status into an exit code
!> (0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O). `femcod bench` lives
!> here (app/bench/, one module per benchmark) because it only measures.
program femcod_main
   use femcod_cli, only: femcod_command, command_arguments
   use femcod_bench, only: bench_command
   use femcod_strings, only: string_type
   use femcod_exit, only: exit_program
   use femcod_start_environment, only: prepare_environment
   implicit none
   type(string_type), allocatable :: args(:)
   integer :: code
   call prepare_environment()
   args = command_arguments()
   code = 0
   if (size(args) >= 1) then
      if (args(1)%s == "bench") then
         call bench_command(args(2:), code)
         call exit_program(code)
      end if
   end if
   call femcod_command(code)
   call exit_program(code)
end program femcod_main
