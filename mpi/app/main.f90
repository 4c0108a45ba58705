!> femcod-mpi: the cg solver (`femcod run --solver cg`) on MPI ranks, for grids beyond one
!> node's memory or time. Run it under mpirun with the options of `femcod run`:
!>     mpirun -np 4 femcod-mpi DECK --loads F1,F2 [-o PREFIX] [--tol T] ...
!>     mpirun -np 4 femcod-mpi --lower scan.h5:/heights --pixel 2 --loads F
!>     mpirun -np 4 femcod-mpi DECK --boundary periodic --approach D1,D2 ...
!>     mpirun -np 4 femcod-mpi --generate self-affine --np N --pixel D --loads F ...
!> Rank 0 reads height files (one copy of the heights, on rank 0 only) and sends each
!> rank its columns; of a text deck every rank reads its own range of the bytes, of an
!> HDF5 deck its own columns (femcod_mpi_input); a generated surface each rank makes its own columns of
!> (femcod_mpi_generate); all ranks solve (femcod_cg's solve on the distributed
!> elastic operator of femcod_mpi_cg) and write PREFIX.h5 together
!> (femcod_mpi_results); rank 0 writes PREFIX.summary.json and prints the summary.
!> Exit codes as femcod's: 0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O,
!> 128 + the signal's number after SIGTERM, SIGINT or SIGUSR1 (no checkpoint: cg keeps none).
program femcod_mpi
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use mpi_f08
   use omp_lib, only: omp_get_max_threads
   use femcod_fftw_mpi, only: start_distributed_fftw, stop_distributed_fftw
   use femcod_kinds, only: dp, i8
   use femcod_memory, only: physical_memory, memory_text, resident_bytes, memory_setting, MEMORY_VARIABLE
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_IO, STATUS_INTERRUPTED, STATUS_NUMERICAL
   use femcod_strings, only: string_type, int_str, sig_str, format_real, json_string, json_number
   use femcod_cli, only: command_arguments, mkdeck_table, parse_mkdeck_arguments
   use femcod_options, only: option_spec, FLAG
   use femcod_generate, only: scene_spec
   use femcod_mpi_generate, only: generate_columns
   use femcod_run_options, only: run_settings, parse_run_arguments
   use femcod_problem, only: contact_problem
   use femcod_deck_h5, only: is_hdf5_file, read_deck_h5_header
   use femcod_mpi_input, only: read_deck_columns, read_text_deck_columns, is_dataset_scene, &
      read_dataset_header, read_dataset_columns
   use femcod_deck_stream, only: read_text_deck_header
   use femcod_heights, only: load_scene, height_file_path
   use femcod_output_guard, only: guard_outputs, OUTPUT_RESULT
   use femcod_files, only: path_exists, remove_file, atomic_rename, write_file, acquire_lock, release_lock, &
      default_prefix
   use femcod_process, only: catch_stop_signals, stop_signal, signal_name, host_name, local_time_iso, &
      openmp_threads, wait_policy_text
   use femcod_mpi_observer, only: signal_observer
   use femcod_clock, only: wall_clock
   use femcod_about, only: FEMCOD_VERSION
   use femcod_exit, only: exit_program
   use femcod_help, only: help_requested
   use femcod_mpi_cg, only: distributed_grid, distributed_state, grid_free, solve_loads, scatter_problem, &
      grid_setup_taking, distributed_rms_slope
   use femcod_love, only: composite_modulus
   use femcod_cg, only: distributed_storage_bytes
   use femcod_mpi_results, only: distributed_run_info, begin_distributed_results, write_distributed_results, figure_block, &
      agree
   use femcod_gap_cg, only: gap_solver_storage_bytes
   use femcod_interface_law, only: make_interface_law
   use femcod_solver_options, only: by_gap_variables, run_shear_model, &
      SOLVER_CG, BOUNDARY_PERIODIC
   use femcod_tangential, only: tangential_request_of, tangential_storage_bytes
   use femcod_mpi_shear, only: tangential_on_ranks
   use femcod_mpi_slab_transform, only: shared_transposes
   use femcod_contact_result, only: stop_reason_text, STOP_LOADS
   use femcod_state_record, only: loads_csv_header, loads_csv_row, state_json, run_info_of
   use femcod_results_json, only: run_header_json
   use femcod_run_summary, only: state_summary_lines
   implicit none

   type(string_type), allocatable :: args(:)
   type(run_settings) :: settings
   type(status_type) :: status
   type(contact_problem) :: problem, header
   type(distributed_grid) :: grid
   type(distributed_state), allocatable :: states(:)
   type(distributed_run_info) :: info
   type(signal_observer) :: observer
   type(string_type), allocatable :: warnings(:)
   character(len=:), allocatable :: prefix, notice, started
   real(dp) :: t_start, t_read, t_solve, t_write, peak, read_peak, constants(4), slope
   real(dp), allocatable :: local(:, :), estimated_mb(:)
   type(string_type), allocatable :: outputs(:), inputs(:)
   integer(i8) :: estimated_rank_bytes
   integer :: provided, rank, ranks, np, block, code, k
   logical :: locked, slab_input, hdf5_input, dataset_input, generating
   character(len=:), allocatable :: fftw_message
   type(scene_spec) :: generated

   call MPI_Init_thread(MPI_THREAD_FUNNELED, provided)
   call MPI_Comm_rank(MPI_COMM_WORLD, rank)
   call MPI_Comm_size(MPI_COMM_WORLD, ranks)
   call wall_clock(t_start)
   started = local_time_iso()
   call start_distributed_fftw(omp_get_max_threads(), fftw_message)
   if (len(fftw_message) > 0) call finish(STATUS_NUMERICAL, fftw_message)
   call catch_stop_signals()
   locked = .false.

   args = command_arguments()
   ! A memory cap (FEMCOD_MEMORY) that does not read is refused, not ignored.
   call memory_setting(estimated_rank_bytes)
   if (estimated_rank_bytes < 0) call finish(STATUS_USAGE, MEMORY_VARIABLE//": expected a number of bytes, "// &
      "optionally with K, M, G or T (KiB to TiB), for example 8G")
   if (help_requested(args)) then
      if (rank == 0) call print_help()
      call finish(0, "")
   end if
   ! --generate KIND and mkdeck's options: the surface made on the ranks (no input file).
   call take_generator_arguments(args, generated, generating, status)
   if (status%code /= 0) call finish(status%code, status%message//" (femcod-mpi --help)")
   ! The solver is cg; `--solver cg` may be given, no other.
   if (.not. any([(args(k)%s == "--solver", k = 1, size(args))])) &
      args = [string_type("--solver"), string_type("cg"), args]
   call parse_run_arguments(args, settings, status)
   if (status%code == 0 .and. generating) then
      if (size(settings%decks) /= 1 .or. settings%from_files) call set_error(status, STATUS_USAGE, "--generate "// &
         "makes the surface on the ranks: give no DECK and no --lower/--upper with it")
   end if
   if (status%code == 0) call refuse_unsupported(settings, status)
   if (status%code /= 0) call finish(status%code, status%message//" (femcod-mpi --help)")
   prefix = settings%prefixes(1)%s

   ! Rank 0 reads the inputs and checks the outputs; the others wait for its verdict.
   if (rank == 0) then
      if (generating) then
         ! Made on the ranks below: nothing to read.
         problem%label = generated%label
      else if (settings%decks(1)%s == "" .and. is_dataset_scene(settings%scene)) then
         ! HDF5 datasets: their sizes here, their columns read by every rank below.
         call read_dataset_header(settings%scene, problem, status)
      else if (settings%decks(1)%s == "") then
         call load_scene(settings%scene, problem, status, warnings=warnings)
         if (allocated(warnings)) then
            do k = 1, size(warnings)
               write(error_unit, '(a)') "femcod-mpi: warning: "//warnings(k)%s
            end do
         end if
      else if (is_hdf5_file(settings%decks(1)%s)) then
         ! An HDF5 deck: its header here, its heights by every rank below.
         call read_deck_h5_header(settings%decks(1)%s, problem, status)
      else
         ! A text deck: its header here, its heights read by the ranks below.
         call read_text_deck_header(settings%decks(1)%s, problem, status)
      end if
      ! femcod's rule for every file it writes: an input is never an output, and an
      ! existing file is replaced only with --force and only if femcod wrote it.
      if (status%code == 0) then
         call output_and_input_names(outputs, inputs)
         call guard_outputs(outputs, inputs, settings%force, OUTPUT_RESULT, status)
      end if
      if (status%code == 0) then
         call acquire_lock(prefix//".lock", status, notice)
         locked = status%code == 0
         if (notice /= "") write(error_unit, '(a)') "femcod-mpi: "//notice
      end if
      if (status%code == 0) info%label = problem%label
   end if
   call agree(status, MPI_COMM_WORLD)
   if (status%code /= 0) call finish(status%code, status%message)

   slab_input = settings%decks(1)%s /= "" .and. .not. generating
   hdf5_input = .false.
   if (slab_input) hdf5_input = is_hdf5_file(settings%decks(1)%s)
   dataset_input = .false.
   if (settings%decks(1)%s == "" .and. .not. generating) dataset_input = is_dataset_scene(settings%scene)
   if (generating) then
      ! Each rank makes its own columns of the surface (FFTW-MPI).
      call generate_columns(generated, MPI_COMM_WORLD, settings%solve%cg, header, local, constants, block, status)
      call agree(status, MPI_COMM_WORLD)
      if (rank == 0) problem = header
      if (status%code /= 0) call finish(status%code, status%message)
   else if (dataset_input) then
      ! Each rank reads its own columns of the height datasets (parallel HDF5, collective).
      call read_dataset_columns(settings%scene, MPI_COMM_WORLD, settings%solve%cg, header, local, constants, &
         block, status, warnings)
      if (rank == 0) then
         problem = header
         do k = 1, size(warnings)
            write(error_unit, '(a)') "femcod-mpi: warning: "//warnings(k)%s
         end do
      end if
      if (status%code /= 0) call finish(status%code, status%message)
   else if (hdf5_input) then
      ! Each rank reads its own columns of the HDF5 deck (parallel HDF5, collective).
      call read_deck_columns(settings%decks(1)%s, MPI_COMM_WORLD, settings%solve%cg, header, local, constants, &
         block, status)
      if (rank == 0) problem = header
      if (status%code /= 0) call finish(status%code, status%message)
   else if (slab_input) then
      ! Every rank reads its range of the text deck's bytes; the heights go to their columns' ranks.
      call read_text_deck_columns(settings%decks(1)%s, MPI_COMM_WORLD, settings%solve%cg, header, local, &
         constants, block, status)
      if (rank == 0) problem = header
      if (status%code /= 0) call finish(status%code, status%message)
   else
      call scatter_problem(problem, MPI_COMM_WORLD, settings%solve%cg, local, constants, block)
   end if
   np = nint(constants(1))
   ! Every rank has its columns now: rank 0 keeps the materials only. Its peak so far is
   ! what reading the inputs took.
   read_peak = peak_memory_mb()
   if (allocated(problem%lower)) deallocate(problem%lower)
   if (allocated(problem%upper)) deallocate(problem%upper)
   ! What each rank is about to allocate, summed over the ranks of a node, against that
   ! node's memory: refused on every rank (exit 4) before the grids are made.
   ! Each state's columns leave memory once written (femcod_mpi_observer): one state's at a time.
   call check_node_memory(np, 1, status)
   if (status%code /= 0) call finish(status%code, status%message)
   ! The grid takes this rank's gaps (`local` is deallocated): the set-up holds them once.
   call grid_setup_taking(grid, MPI_COMM_WORLD, np, block, local, constants(2), constants(3), constants(4), &
      settings%solve%cg, status, settings%solve%boundary == BOUNDARY_PERIODIC)
   ! kappa's slope scale: the initial gaps' rms slope, from every rank's columns.
   slope = 0
   if (status%code == 0) slope = distributed_rms_slope(grid)
   call wall_clock(t_read)
   ! PREFIX.h5's temporary, begun before the solve: each state's maps go there as soon as
   ! it is solved, with its figures' blocks to rank 0 (femcod_mpi_observer).
   observer%path = prefix//".h5.part"
   observer%figure = figure_block(np)
   observer%tangential = settings%solve%tangential
   call begin_distributed_results(observer%path, grid, size(targets()), status)
   if (status%code == 0) call solve_loads(grid, problem, targets(), settings%solve%cg, states, status, observer, &
      settings%solve%hardness, settings%solve%plastic, by_approach(), make_interface_law(settings%solve%adhesion, &
      settings%solve%work, settings%solve%range, grid%pixel, settings%solve%plastic, settings%solve%hardness), &
      run_shear_model(settings%solve))
   if (status%code == 0 .and. settings%solve%tangential) call tangential_on_ranks(grid, problem, &
      tangential_request_of(settings%solve), states, status, observer)
   call wall_clock(t_solve)
   ! A state's maps that could not be written stopped the solve: that is the error.
   if (observer%written%code /= 0) status = observer%written
   if (status%code /= 0) then
      if (status%code == STATUS_INTERRUPTED) call finish(128 + stop_signal(), signal_name(stop_signal())//": "// &
         status%message)
      call finish(status%code, status%message)
   end if

   ! Results: PREFIX.h5 by all ranks (into a temporary name, renamed by rank 0), then the
   ! summary.
   peak = peak_memory_mb()
   allocate(info%peak_mb(ranks))
   call MPI_Gather(peak, 1, MPI_DOUBLE_PRECISION, info%peak_mb, 1, MPI_DOUBLE_PRECISION, 0, MPI_COMM_WORLD)
   allocate(estimated_mb(ranks))
   call MPI_Gather(real(estimated_rank_bytes, dp)/1024**2, 1, MPI_DOUBLE_PRECISION, estimated_mb, 1, &
      MPI_DOUBLE_PRECISION, 0, MPI_COMM_WORLD)
   ! The run's record as femcod run's (its columns from the options), on the ranks.
   info%run_info = run_info_of(settings%solve)
   info%solver = "cg (femcod-mpi)"
   info%rms_slope = slope
   if (rank == 0) info%composite_modulus = composite_modulus(problem%young(1:2), problem%poisson(1:2))
   ! The scene as the summary names it (rank 0 holds the deck's header; the grid is the ranks').
   problem%np = np
   problem%pixel = grid%pixel
   info%version = FEMCOD_VERSION
   info%command_line = "femcod-mpi "//settings%command_line
   info%host = host_name()
   info%started = started
   info%finished = local_time_iso()
   info%ranks = ranks
   info%threads = openmp_threads()
   info%wait_policy = wait_policy_text()
   if (.not. allocated(info%label)) info%label = ""
   info%wall_seconds = t_solve - t_start
   call write_distributed_results(prefix//".h5.part", grid, states, info, status)
   if (rank == 0) then
      if (status%code == 0) call atomic_rename(prefix//".h5.part", prefix//".h5", status)
      if (status%code /= 0) call remove_file(prefix//".h5.part")
      if (status%code == 0) call write_file(prefix//".loads.csv", loads_csv(), status)
      ! Each load's two figures, drawn as it was solved (femcod_mpi_observer).
      do k = 1, size(states)
         if (status%code == 0) call write_file(prefix//".pressure_"//int_str(k)//".svg", observer%pressure_svg(k)%s, &
            status)
         if (status%code == 0) call write_file(prefix//".gap_"//int_str(k)//".svg", observer%gap_svg(k)%s, status)
      end do
      call wall_clock(t_write)
      if (status%code == 0) call write_file(prefix//".summary.json", summary_json(), status)
      if (status%code /= 0) then
         ! No partial result set: what was written goes.
         call remove_file(prefix//".h5")
         call remove_file(prefix//".loads.csv")
         do k = 1, size(states)
            call remove_file(prefix//".pressure_"//int_str(k)//".svg")
            call remove_file(prefix//".gap_"//int_str(k)//".svg")
         end do
      end if
      if (status%code == 0 .and. .not. settings%quiet) call print_summary()
   end if
   call agree(status, MPI_COMM_WORLD)
   call grid_free(grid)
   if (status%code /= 0) call finish(status%code, status%message)
   call finish(0, "")

contains

   !> The options femcod run has and femcod-mpi does not (yet): refused, not ignored.
   !> The ranks run femcod_cg's fixed-load and fixed-approach solve (with --plastic and
   !> --kernel-radius), its gap-variable path (--adhesion, or --plastic with --approach)
   !> and the tangential step (--tangential, --slip) on the free surface or the periodic
   !> cell.
   subroutine refuse_unsupported(settings, status)
      type(run_settings), intent(in) :: settings
      type(status_type), intent(inout) :: status
      associate(o => settings%solve)
         if (o%solver /= SOLVER_CG) then
            call set_error(status, STATUS_USAGE, "--solver: the MPI ranks run the fixed-load solver only (cg); "// &
               "the event solvers run on one node: femcod run")
         else if (size(settings%decks) /= 1) then
            call set_error(status, STATUS_USAGE, "one deck per run: run several decks as a job array "// &
               "(doc/cluster.md)")
         else if (size(targets()) == 0) then
            call set_error(status, STATUS_USAGE, "give the loads or the approaches: --loads F1,F2,... or "// &
               "--approach D1,D2,...")
         else if (o%boundary == BOUNDARY_PERIODIC .and. o%cg%kernel_radius > 0) then
            call set_error(status, STATUS_USAGE, "--kernel-radius with --boundary periodic: the ranks take the "// &
               "periodic kernel's spectrum in closed form, untruncated; it runs on one node: femcod run --solver cg")
         end if
      end associate
   end subroutine refuse_unsupported

   !> `--generate KIND` with mkdeck's options for it (femcod mkdeck --help): taken out of
   !> `args` into `spec`, and KIND left in their place as the run's deck name (it names
   !> the results unless -o does). Nothing else changes: the rest are run's options.
   subroutine take_generator_arguments(args, spec, generating, status)
      type(string_type), allocatable, intent(inout) :: args(:)
      type(scene_spec), intent(out) :: spec
      logical, intent(out) :: generating
      type(status_type), intent(inout) :: status
      character(len=*), parameter :: NOT_FOR_RANKS = " --output --force --verification --dir --file --maxcont "// &
         "--height-unit "
      type(option_spec), allocatable :: table(:)
      type(string_type), allocatable :: taken(:), kept(:)
      character(len=:), allocatable :: output, verification, dir
      integer :: k, m, j, nt, nk
      logical :: labelled
      generating = any([(args(k)%s == "--generate", k = 1, size(args))])
      if (.not. generating) return
      table = mkdeck_table()
      ! Filled element by element (gfortran mishandles constructors of these).
      allocate(taken(size(args) + 2), kept(size(args)))
      nt = 1
      nk = 0
      labelled = .false.
      k = 1
      do while (k <= size(args))
         if (args(k)%s == "--generate") then
            if (k == size(args)) then
               call set_error(status, STATUS_USAGE, "--generate needs a KIND (self-affine)")
               return
            end if
            taken(1)%s = args(k + 1)%s
            nk = nk + 1
            kept(nk)%s = args(k + 1)%s
            k = k + 2
            cycle
         end if
         ! One of mkdeck's options for the surface (not its file and output options).
         m = 0
         if (index(NOT_FOR_RANKS, " "//args(k)%s//" ") == 0) then
            do j = 1, size(table)
               if (table(j)%name == args(k)%s) m = j
            end do
         end if
         if (m == 0) then
            nk = nk + 1
            kept(nk)%s = args(k)%s
            k = k + 1
            cycle
         end if
         labelled = labelled .or. args(k)%s == "--label"
         nt = nt + 1
         taken(nt)%s = args(k)%s
         if (table(m)%kind /= FLAG .and. k < size(args)) then
            nt = nt + 1
            taken(nt)%s = args(k + 1)%s
            k = k + 1
         end if
         k = k + 1
      end do
      taken(nt + 1)%s = "--output"
      taken(nt + 2)%s = "(the ranks)"
      call parse_mkdeck_arguments(taken(1:nt + 2), spec, output, verification, dir, status)
      if (status%code /= 0) return
      if (.not. labelled) spec%label = "femcod-mpi --generate "//spec%kind
      args = kept(1:nk)
   end subroutine take_generator_arguments

   !> Which input path the run took (the summary's "input").
   function input_path() result(text)
      character(len=:), allocatable :: text
      if (generating) then
         text = "made on the ranks: "//generated%kind//", NP "//int_str(generated%np)//", seed "// &
            int_str(generated%seed)
      else if (dataset_input) then
         text = "HDF5 height datasets, each rank its own columns"
      else if (hdf5_input) then
         text = "HDF5 deck, each rank its own columns"
      else if (slab_input) then
         text = "text deck, each rank its own range of the bytes, each height sent to its column's rank"
      else
         text = "rank 0 reads, sends columns"
      end if
   end function input_path

   !> Displacement control: --approach given.
   logical function by_approach()
      by_approach = .false.
      if (allocated(settings%solve%approaches)) by_approach = size(settings%solve%approaches) > 0
   end function by_approach

   !> The targets: the approaches (nm) with --approach, else the loads (nN).
   function targets() result(values)
      real(dp), allocatable :: values(:)
      if (by_approach()) then
         values = settings%solve%approaches
      else
         values = settings%solve%loads
      end if
   end function targets

   !> Each rank's storage: what it holds now and its share of the distributed solver's
   !> arrays (distributed_storage_bytes over the ranks: the grid is split in column slabs;
   !> with the gap variables their transform grid too). The ranks that
   !> share a node (MPI_COMM_TYPE_SHARED) share its memory, so their sum, with the Love
   !> table they share when every rank is on one node, is compared with it; the largest
   !> node's sum is reported.
   subroutine check_node_memory(n, nstates, st)
      integer, intent(in) :: n, nstates
      type(status_type), intent(inout) :: st
      type(MPI_Comm) :: node
      integer(i8) :: on_node, worst, may, table
      integer :: node_ranks
      estimated_rank_bytes = distributed_storage_bytes(n, nstates, settings%solve%boundary == BOUNDARY_PERIODIC, &
         settings%solve%plastic, shared_transposes(MPI_COMM_WORLD))
      ! The gap variables: their transform grid besides the fixed-load solver's grid.
      if (by_gap_variables(settings%solve)) estimated_rank_bytes = estimated_rank_bytes + &
         gap_solver_storage_bytes(n, nstates, settings%solve%boundary == BOUNDARY_PERIODIC, settings%solve%plastic)
      ! The tangential step: its operator and grids besides the solver's.
      if (settings%solve%tangential) estimated_rank_bytes = estimated_rank_bytes + tangential_storage_bytes(n)
      estimated_rank_bytes = resident_bytes() + (estimated_rank_bytes + ranks - 1)/ranks
      call MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, node)
      call MPI_Comm_size(node, node_ranks)
      ! The direct corrections' float32 Love table when every rank is on one node: in each
      ! rank's resident memory (each reads all of it), on the node once (femcod_mpi_cg's
      ! table_window_setup).
      table = 0
      if (node_ranks == ranks .and. settings%solve%cg%direct_corrections > 0) table = 4*int(n, i8)**2
      estimated_rank_bytes = estimated_rank_bytes + table
      call MPI_Allreduce(estimated_rank_bytes, on_node, 1, MPI_INTEGER8, MPI_SUM, node)
      on_node = on_node - (node_ranks - 1)*table
      call MPI_Comm_free(node)
      may = physical_memory()
      worst = 0
      if (may > 0 .and. on_node > may) worst = on_node
      call MPI_Allreduce(MPI_IN_PLACE, worst, 1, MPI_INTEGER8, MPI_MAX, MPI_COMM_WORLD)
      if (worst > 0) call set_error(st, STATUS_NUMERICAL, "NP = "//int_str(n)//" on "//int_str(ranks)// &
         " ranks: the ranks of one node need about "//memory_text(worst)//" (their share of the solver's "// &
         "arrays and what they hold already), a node may use "//memory_text(may)//"; give more nodes")
   end subroutine check_node_memory

   !> The files this run writes (PREFIX.h5, .summary.json, .loads.csv, a pressure and a
   !> gap figure per load)
   !> and the files it reads (the deck, or the height files); filled element by element.
   subroutine output_and_input_names(outputs, inputs)
      type(string_type), allocatable, intent(out) :: outputs(:), inputs(:)
      integer :: j, nloads
      nloads = size(targets())
      allocate(outputs(3 + 2*nloads))
      outputs(1)%s = prefix//".h5"
      outputs(2)%s = prefix//".summary.json"
      outputs(3)%s = prefix//".loads.csv"
      do j = 1, nloads
         outputs(2 + 2*j)%s = prefix//".pressure_"//int_str(j)//".svg"
         outputs(3 + 2*j)%s = prefix//".gap_"//int_str(j)//".svg"
      end do
      if (generating) then
         allocate(inputs(0))
      else if (settings%decks(1)%s /= "") then
         allocate(inputs(1))
         inputs(1)%s = settings%decks(1)%s
      else if (settings%scene%second_file /= "") then
         allocate(inputs(2))
         inputs(1)%s = height_file_path(settings%scene%matrix_file)
         inputs(2)%s = height_file_path(settings%scene%second_file)
      else
         allocate(inputs(1))
         inputs(1)%s = height_file_path(settings%scene%matrix_file)
      end if
   end subroutine output_and_input_names

   !> Releases the lock, reports `message` (rank 0), ends MPI and exits with `code`.
   subroutine finish(code, message)
      integer, intent(in) :: code
      character(len=*), intent(in) :: message
      ! A run that ends without results leaves no temporary result file.
      if (rank == 0 .and. code /= 0 .and. allocated(observer%path)) call remove_file(observer%path)
      if (rank == 0 .and. locked) call release_lock(prefix//".lock")
      if (rank == 0 .and. code /= 0 .and. message /= "") write(error_unit, '(a)') "femcod-mpi: "//message
      call stop_distributed_fftw()
      call MPI_Finalize()
      call exit_program(code)
   end subroutine finish

   !> This process's peak resident memory (MB), from /proc/self/status (VmHWM); 0 where
   !> the system has no such file.
   real(dp) function peak_memory_mb()
      character(len=256) :: line
      integer :: unit, ios
      real(dp) :: kb
      peak_memory_mb = 0
      open(newunit=unit, file="/proc/self/status", status="old", action="read", iostat=ios)
      if (ios /= 0) return
      do
         read(unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (line(1:6) == "VmHWM:") then
            read(line(7:), *, iostat=ios) kb
            if (ios == 0) peak_memory_mb = kb/1024
            exit
         end if
      end do
      close(unit)
   end function peak_memory_mb

   !> PREFIX.loads.csv: the serial writer's rows (io/femcod_state_record).
   function loads_csv() result(text)
      character(len=:), allocatable :: text
      integer :: s
      text = loads_csv_header(info%run_info)//new_line('a')
      do s = 1, size(states)
         text = text//loads_csv_row(states(s)%state_values, grid%pixel, np, info%run_info)//new_line('a')
      end do
   end function loads_csv

   !> PREFIX.summary.json in the serial summary's layout (io/femcod_results_json: the
   !> run, the scene, each state's values), each state with the ranks' work on it, then
   !> the ranks' times and memory.
   function summary_json() result(text)
      character(len=:), allocatable :: text
      character(len=1), parameter :: nl = new_line('a')
      integer :: s
      text = run_header_json(prefix, problem, info%run_info)//'  "steps": 0,'//nl//'  "stopped": '// &
         json_string(stop_reason_text(STOP_LOADS))//','//nl//'  "loads": ['//nl
      do s = 1, size(states)
         associate(st => states(s))
            text = text//'    '//state_json(st%state_values, s, size(states), grid%pixel, np, info%run_info, &
               st%cg, "", ', "coarse_iterations": '//int_str(st%cg%coarse_iterations)//', "convolutions": '// &
               int_str(st%cg%convolutions)//', "time_s": '//json_number(st%seconds)// &
               ', "transform_s": '//json_number(st%transform_seconds)//', "communication_s": '// &
               json_number(st%communication_seconds))//trim(merge(",", " ", s < size(states)))//nl
         end associate
      end do
      text = text//'  ],'//nl//'  "wall_time_s": '//json_number(t_solve - t_read)//','//nl// &
         '  "timings_s": {"read_inputs": '//json_number(t_read - t_start)//', "solve": '// &
         json_number(t_solve - t_read)//', "write": '//json_number(t_write - t_solve)//', "total": '// &
         json_number(t_write - t_start)//'},'//nl// &
         '  "read_time_s": '//json_number(t_read - t_start)//', "solve_time_s": '//json_number(t_solve - t_read)// &
         ', "write_time_s": '//json_number(t_write - t_solve)//','//nl// &
         '  "input": '//json_string(input_path())//','//nl// &
         '  "mpi_ranks": '//int_str(ranks)//', "threads_per_rank": '//int_str(info%threads)//','//nl// &
         '  "memory_bytes": {"estimated_peak": '//int_str(nint(maxval(estimated_mb)*1024**2, i8))//', "peak": '// &
         int_str(nint(maxval(info%peak_mb)*1024**2, i8))//'},'//nl// &
         '  "peak_memory_MB_per_rank": '//json_list(info%peak_mb)//','//nl// &
         '  "estimated_peak_memory_MB_per_rank": '//json_list(estimated_mb)//','//nl// &
         '  "read_peak_memory_MB": '//json_number(read_peak)//nl//'}'//nl
   end function summary_json

   !> [a, b, ...] of numbers.
   function json_list(values) result(text)
      real(dp), intent(in) :: values(:)
      character(len=:), allocatable :: text
      integer :: s
      text = '['
      do s = 1, size(values)
         text = text//json_number(values(s))//trim(merge(", ", "  ", s < size(values)))
      end do
      text = trim(text)//']'
   end function json_list

   subroutine print_summary()
      type(string_type), allocatable :: lines(:)
      integer :: s, m
      write(output_unit, '(a)') "femcod-mpi: "//info%label
      write(output_unit, '(a)') "  grid "//int_str(np)//" x "//int_str(np)//", pixel "//format_real(grid%pixel)// &
         " nm, "//trim(merge("periodic cell", "free surface ", settings%solve%boundary == BOUNDARY_PERIODIC))//"; "// &
         int_str(ranks)//" MPI ranks x "//int_str(info%threads)//" threads"
      do s = 1, size(states)
         ! femcod run's lines of a state (cli/femcod_run_summary), then the ranks' work on it.
         lines = state_summary_lines(states%state_values, s, grid%pixel, settings%solve, states(s)%cg%approach_bound, "")
         do m = 1, size(lines)
            write(output_unit, '(a)') lines(m)%s
         end do
         associate(st => states(s))
            write(output_unit, '(a)') "              "//int_str(st%cg%iterations)//" iterations (+ "// &
               int_str(st%cg%coarse_iterations)//" on coarser grids), "//int_str(st%cg%convolutions)// &
               " fresh convolutions, residual "//sig_str(st%cg%residual, 2)//", "//sig_str(st%seconds, 3)// &
               " s (rank 0: transforms "//sig_str(st%transform_seconds, 3)//" s, communication "// &
               sig_str(st%communication_seconds, 3)//" s)"
         end associate
      end do
      write(output_unit, '(a)') "  peak memory per rank: "//sig_str(maxval(info%peak_mb), 4)//" MB (largest), "// &
         sig_str(minval(info%peak_mb), 4)//" MB (smallest)"
      write(output_unit, '(a)') "  wall time "//sig_str(t_write - t_start, 3)//" s: reading "// &
         sig_str(t_read - t_start, 3)//" s, solving "//sig_str(t_solve - t_read, 3)//" s, writing "// &
         sig_str(t_write - t_solve, 3)//" s"
      write(output_unit, '(a)') "  results: "//prefix//".h5, .summary.json, .loads.csv, .pressure_<k>.svg, .gap_<k>.svg"
   end subroutine print_summary

   subroutine print_help()
      write(output_unit, '(a)') "usage: mpirun -np P femcod-mpi DECK --loads F1,F2,... [options]"
      write(output_unit, '(a)') "       mpirun -np P femcod-mpi --lower FILE[:DATASET] --pixel D --loads F1,... [options]"
      write(output_unit, '(a)') "       mpirun -np P femcod-mpi --generate self-affine --np N --pixel D [--hurst H --rms R"
      write(output_unit, '(a)') "         --seed S ...] --loads F1,... [options]   (the surface made on the ranks, as"
      write(output_unit, '(a)') "         femcod mkdeck self-affine makes it; no input file)"
      write(output_unit, '(a)') ""
      write(output_unit, '(a)') "The fixed-load solver (femcod run --solver cg) with the grid split in column slabs"
      write(output_unit, '(a)') "across MPI ranks: FFTW-MPI transforms, parallel HDF5 output. The options are those"
      write(output_unit, '(a)') "of femcod run (femcod run --help) for the cg solver, with the"
      write(output_unit, '(a)') "same iteration (femcod_cg on the ranks' elastic operator):"
      write(output_unit, '(a)') "  --loads F1,F2,...  total loads (nN), or --approach D1,D2,... approaches (nm)"
      write(output_unit, '(a)') "  --boundary free|periodic, --plastic --hardness H, --kernel-radius R (free surface,"
      write(output_unit, '(a)') "  --loads), --adhesion dugdale|exponential --work W --range R (with --approach),"
      write(output_unit, '(a)') "  --shear-strength TAU0 --shear-slope ALPHA (friction from the pressures), --tol T"
      write(output_unit, '(a)') "  (default 1e-8), --tangential Q or --slip S with --friction MU (a tangential"
      write(output_unit, '(a)') "  step with Coulomb friction at each state),"
      write(output_unit, '(a)') "  --max-iterations N, -o PREFIX, --outdir DIR, --force, --quiet; the height-file"
      write(output_unit, '(a)') "  options (--lower, --upper, --pixel, --young, --poisson, --height-unit, ...)"
      write(output_unit, '(a)') "Refused (they run on one node with femcod run): --kernel-radius on the periodic"
      write(output_unit, '(a)') "cell, several decks, the event solvers."
      write(output_unit, '(a)') "Writes PREFIX.h5 (/deck, /loads/<kkk> with pressure and gap maps and, with a"
      write(output_unit, '(a)') "tangential step, shear_x, shear_y, stick and slip, /run with the"
      write(output_unit, '(a)') "peak memory of every rank) and PREFIX.summary.json. Exit codes: 0 ok, 2 usage,"
      write(output_unit, '(a)') "3 bad input, 4 numerical failure, 5 I/O, 128 + signal after SIGTERM/SIGINT/SIGUSR1."
      write(output_unit, '(a)') "Ranks and threads: doc/cluster.md."
   end subroutine print_help
end program femcod_mpi
