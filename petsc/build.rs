//! Finds PETSc (pkg-config `PETSc`; with `PETSC_DIR` [and `PETSC_ARCH`] set, the `.pc` file of that
//! installation) and the MPI headers it includes (pkg-config `ompi-c`, `mpich` or `mpi`, else
//! `mpicc`'s compile line), generates the binding of an allowlist of petscksp.h with bindgen, and
//! compiles the few MPI calls of `src/shim.c` (MPI's handles are macros that bindgen cannot
//! translate portably).

use std::env;
use std::path::PathBuf;
use std::process::Command;

/// The PETSc functions the crate wraps (petscsys.h, petscvec.h, petscmat.h, petscpc.h, petscksp.h).
const FUNCTIONS: &[&str] = &[
    "PetscInitializeNoArguments",
    "PetscInitialized",
    "PetscFinalize",
    "PetscFinalized",
    "PetscPushErrorHandler",
    "PetscErrorMessage",
    "PetscOptionsInsertString",
    "PetscGetVersionNumber",
    "VecCreateMPI",
    "VecDuplicate",
    "VecGetOwnershipRange",
    "VecGetArray",
    "VecRestoreArray",
    "VecGetArrayRead",
    "VecRestoreArrayRead",
    "VecNorm",
    "VecDestroy",
    "VecScatterCreateToAll",
    "VecScatterBegin",
    "VecScatterEnd",
    "VecScatterDestroy",
    "MatCreateAIJ",
    "MatSetValues",
    "MatZeroEntries",
    "MatAssemblyBegin",
    "MatAssemblyEnd",
    "MatSetOption",
    "MatGetOwnershipRange",
    "MatMult",
    "MatDestroy",
    "MatNullSpaceCreate",
    "MatNullSpaceDestroy",
    "MatSetNearNullSpace",
    "KSPCreate",
    "KSPSetOperators",
    "KSPSetType",
    "KSPGetPC",
    "KSPSetPCSide",
    "KSPSetTolerances",
    "KSPGetTolerances",
    "KSPSetFromOptions",
    "KSPSetOptionsPrefix",
    "KSPSetUp",
    "KSPSolve",
    "KSPGetIterationNumber",
    "KSPGetConvergedReason",
    "KSPGetConvergedReasonString",
    "KSPGetType",
    "KSPDestroy",
    "KSPGMRESSetRestart",
    "PCSetType",
    "PCGetType",
    "PCFactorSetMatSolverType",
    "PCFactorGetMatSolverType",
    "PCGetFailedReason",
    "PCApply",
    "PCFactorGetMatrix",
    "MatMumpsGetInverseTranspose",
    "MatMumpsGetIcntl",
    "MatMumpsSetIcntl",
    "MatGetRow",
    "MatRestoreRow",
];

/// The binding's types, for documentation without PETSc.
const STAND_INS: &str = "
pub type PetscInt = ::std::os::raw::c_int;
pub type PetscErrorCode = ::std::os::raw::c_int;
pub type PetscErrorType = ::std::os::raw::c_uint;
pub type PetscBool = ::std::os::raw::c_uint;
pub type MPI_Comm = *mut ::std::ffi::c_void;
pub type Vec = *mut ::std::ffi::c_void;
pub type Mat = *mut ::std::ffi::c_void;
pub type KSP = *mut ::std::ffi::c_void;
pub type PC = *mut ::std::ffi::c_void;
pub type VecScatter = *mut ::std::ffi::c_void;
";

fn probe_petsc() -> Result<pkg_config::Library, String> {
    if let Ok(dir) = env::var("PETSC_DIR") {
        let arch = env::var("PETSC_ARCH").unwrap_or_default();
        let pc = PathBuf::from(dir).join(arch).join("lib/pkgconfig");
        let old = env::var("PKG_CONFIG_PATH").unwrap_or_default();
        env::set_var("PKG_CONFIG_PATH", if old.is_empty() { pc.display().to_string() } else { format!("{}:{old}", pc.display()) });
    }
    let mut errors = Vec::new();
    for name in ["PETSc", "petsc"] {
        match pkg_config::Config::new().atleast_version("3.15").probe(name) {
            Ok(lib) => return Ok(lib),
            Err(e) => errors.push(e.to_string()),
        }
    }
    Err(format!(
        "PETSc (3.15 or newer) not found through pkg-config (`PETSc`), nor under PETSC_DIR/PETSC_ARCH; \
         on Debian: apt-get install libpetsc-real-dev openmpi-bin libopenmpi-dev libclang-dev pkg-config{}",
        if errors.is_empty() { "" } else { " (pkg-config found no PETSc.pc)" }
    ))
}

/// Include directories of MPI (petscsys.h includes mpi.h), and the link lines for the shim's own
/// MPI calls.
fn probe_mpi() -> Vec<PathBuf> {
    for name in ["ompi-c", "mpich", "mpi"] {
        if let Ok(lib) = pkg_config::Config::new().probe(name) {
            return lib.include_paths;
        }
    }
    let words = |args: &[&str]| -> Vec<String> {
        Command::new("mpicc")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).split_whitespace().map(String::from).collect())
            .unwrap_or_default()
    };
    let mut compile = words(&["--showme:compile"]);
    let mut link = words(&["--showme:link"]);
    if compile.is_empty() {
        // MPICH's wrapper: one line with both
        compile = words(&["-show"]);
        link = compile.clone();
    }
    for w in &link {
        if let Some(d) = w.strip_prefix("-L") {
            println!("cargo:rustc-link-search=native={d}");
        } else if let Some(l) = w.strip_prefix("-l") {
            println!("cargo:rustc-link-lib={l}");
        }
    }
    compile.iter().filter_map(|w| w.strip_prefix("-I")).map(PathBuf::from).collect()
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/shim.c");
    println!("cargo:rerun-if-env-changed=PETSC_DIR");
    println!("cargo:rerun-if-env-changed=PETSC_ARCH");
    println!("cargo::rustc-check-cfg=cfg(petsc_missing)");
    let petsc = match probe_petsc() {
        Ok(p) => p,
        Err(e) => {
            // `cargo doc --workspace` on a machine without PETSc still documents the crate: the
            // types of the binding as stand-ins, and a compile error for any real build (lib.rs)
            println!("cargo:warning=stamp-petsc: {e}");
            println!("cargo:rustc-cfg=petsc_missing");
            // probe again at the next build: PETSc may have been installed since (a path that
            // does not exist makes cargo rerun this script every time, until PETSc is found)
            println!("cargo:rerun-if-changed=petsc-not-found-probe-again");
            let out = PathBuf::from(env::var("OUT_DIR").unwrap());
            std::fs::write(out.join("bindings.rs"), STAND_INS).expect("write bindings.rs");
            return;
        }
    };
    // and again when the PETSc.pc that was found changes (another PETSc installed over it)
    if let Ok(o) = Command::new("pkg-config").args(["--variable=pcfiledir", "PETSc"]).output() {
        let dir = String::from_utf8_lossy(&o.stdout).trim().to_string();
        if o.status.success() && !dir.is_empty() {
            println!("cargo:rerun-if-changed={dir}/PETSc.pc");
        }
    }
    let mut includes = petsc.include_paths.clone();
    includes.extend(probe_mpi());

    let mut builder = bindgen::Builder::default()
        .header_contents("wrapper.h", "#include <petscksp.h>\n")
        .parse_callbacks(Box::new(bindgen::CargoCallbacks::new()))
        .allowlist_var("PETSC_COMM_WORLD")
        .allowlist_var("PETSC_DECIDE")
        .allowlist_var("PETSC_DETERMINE")
        .allowlist_var("PETSC_DEFAULT")
        .allowlist_var("PETSC_VERSION_.*")
        .allowlist_type("PetscErrorType")
        .allowlist_type("InsertMode")
        .allowlist_type("ScatterMode")
        .allowlist_type("NormType")
        .allowlist_type("MatAssemblyType")
        .allowlist_type("MatOption")
        .allowlist_type("PCSide")
        .allowlist_type("KSPConvergedReason")
        .allowlist_type("PCFailedReason")
        .default_enum_style(bindgen::EnumVariation::Consts)
        .layout_tests(false);
    for f in FUNCTIONS {
        builder = builder.allowlist_function(f);
    }
    for dir in &includes {
        builder = builder.clang_arg(format!("-I{}", dir.display()));
    }
    let bindings = builder.generate().unwrap_or_else(|e| panic!("stamp-petsc: bindgen over petscksp.h failed ({e}); include path {includes:?}"));
    let out = PathBuf::from(env::var("OUT_DIR").unwrap());
    bindings.write_to_file(out.join("bindings.rs")).expect("write bindings.rs");

    let mut cc = cc::Build::new();
    cc.file("src/shim.c").warnings(true);
    for dir in &includes {
        cc.include(dir);
    }
    cc.compile("stamp_petsc_shim");
}
