!> The femcod command: `femcod <command> [options]`. Everything numerical lives in
!> src/; this program parses the command line and turns a status into an exit code
!> (0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O).
program femcod_main
   use femcod_cli, only: femcod_command
   use femcod_exit, only: exit_program
   implicit none
   integer :: code
   call femcod_command(code)
   call exit_program(code)
end program femcod_main
