//! The C ABI called from Rust: every error path that does not need a real mesh, plus the output
//! paths on an injected mesh. (ctests/ffi runs the same ground from C under AddressSanitizer.)

use super::*;
use crate::mesh::TetMesh;
use crate::run::report::Report;
use glam::DVec3;
use std::ffi::{c_char, c_void, CStr};
use std::ptr::{null, null_mut};

struct Handle(*mut sm_mesher);
impl Drop for Handle {
    fn drop(&mut self) {
        // SAFETY: `self.0` came from `sm_create` and is destroyed once, here.
        unsafe { sm_destroy(self.0) }
    }
}

fn new() -> Handle {
    let m = sm_create();
    assert!(!m.is_null());
    Handle(m)
}

fn text(p: *const c_char) -> String {
    assert!(!p.is_null());
    // SAFETY: the library returns NUL-terminated strings that live at least until the next call.
    unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
}

fn last_error(h: &Handle) -> String {
    // SAFETY: live handle.
    text(unsafe { sm_last_error(h.0) })
}

const CUBE_XYZ: [f64; 24] = [
    0., 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0., 0., 0., 1., 1., 0., 1., 0., 1., 1., 1., 1., 1.,
];
const CUBE_FACES: [[u32; 4]; 6] = [
    [0, 2, 3, 1],
    [4, 5, 7, 6],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 4, 6, 2],
    [1, 3, 7, 5],
];

fn cube() -> Handle {
    let h = new();
    // SAFETY: live handle, arrays of the stated sizes.
    unsafe {
        assert_eq!(sm_add_vertices(h.0, CUBE_XYZ.as_ptr(), 8), SM_OK);
        for (k, f) in CUBE_FACES.iter().enumerate() {
            assert_eq!(sm_add_facet(h.0, f.as_ptr(), 4, k as i32 + 1), SM_OK);
        }
    }
    h
}

/// A two-tet mesh installed as if refined.
fn inject(h: &Handle) {
    let mesh = TetMesh {
        vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE],
        tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]],
        tet_regions: vec![7, 8],
        boundary: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2]],
        boundary_markers: vec![1, 2, 3],
    };
    let report = Report {
        n_vertices: 5,
        n_tets: 2,
        n_boundary_faces: 3,
        max_rho: 1.5,
        tets_below_deg: [0, 1, 2, 3],
        complete: true,
        ..Report::default()
    };
    // SAFETY: live handle, not borrowed elsewhere.
    let handle = unsafe { &*h.0 };
    handle
        .state
        .borrow_mut()
        .mesher
        .install_output(mesh, report);
}

#[test]
fn status_codes_are_fixed_and_described() {
    for (i, (code, text_)) in status::STATUS_TEXTS.iter().enumerate() {
        assert_eq!(*code, i as sm_status, "codes are never renumbered");
        assert_eq!(text(sm_status_str(*code)), text_.to_str().unwrap());
    }
    assert_eq!(
        (
            SM_OK,
            SM_ERR_NULL,
            SM_ERR_INVALID_ARGUMENT,
            SM_ERR_INVALID_INPUT
        ),
        (0, 1, 2, 3)
    );
    assert_eq!(
        (SM_ERR_SPACING, SM_ERR_CANCELLED, SM_ERR_BUFFER_TOO_SMALL),
        (4, 5, 6)
    );
    assert_eq!(
        (SM_ERR_NOT_REFINED, SM_ERR_IO, SM_ERR_PANIC, SM_ERR_POISONED),
        (7, 8, 9, 10)
    );
    assert_eq!((SM_ERR_INTERNAL, SM_ERR_BUSY), (11, 12));
    assert_eq!(text(sm_status_str(-1)), "unknown status");
    assert_eq!(text(sm_status_str(999)), "unknown status");
    assert_eq!(text(sm_version()), env!("CARGO_PKG_VERSION"));
}

/// The header's SM_VERSION_* macros, sm_version() and Cargo.toml agree (bump all three together).
#[test]
fn version_macros_match_the_library() {
    let macros = format!("{SM_VERSION_MAJOR}.{SM_VERSION_MINOR}.{SM_VERSION_PATCH}");
    assert_eq!(
        macros,
        env!("CARGO_PKG_VERSION"),
        "SM_VERSION_* in src/ffi/mesher.rs vs Cargo.toml"
    );
    assert_eq!(text(sm_version()), macros);
    let header =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/include/slivermesh.h"))
            .unwrap();
    for (name, v) in [
        ("SM_VERSION_MAJOR", SM_VERSION_MAJOR),
        ("SM_VERSION_MINOR", SM_VERSION_MINOR),
        ("SM_VERSION_PATCH", SM_VERSION_PATCH),
    ] {
        assert!(
            header.contains(&format!("#define {name} {v}\n")),
            "include/slivermesh.h lacks `#define {name} {v}`"
        );
    }
    // include/slivermesh.f90 mirrors sm_quality field by field and checks this size too.
    assert_eq!(std::mem::size_of::<sm_quality>(), 168);
}

#[test]
fn null_handle_everywhere() {
    let m = null_mut::<sm_mesher>();
    let ids = [0u32, 1, 2];
    let mut q = sm_quality::default();
    let mut buf = [0f64; 3];
    let mut v = 0.0;
    // SAFETY: NULL handles are allowed everywhere; the other pointers are valid.
    unsafe {
        sm_destroy(m);
        assert_eq!(sm_add_vertices(m, buf.as_ptr(), 1), SM_ERR_NULL);
        assert_eq!(sm_add_facet(m, ids.as_ptr(), 3, 0), SM_ERR_NULL);
        assert_eq!(sm_add_facet_hole(m, ids.as_ptr(), 3), SM_ERR_NULL);
        assert_eq!(sm_add_hole(m, 0., 0., 0.), SM_ERR_NULL);
        assert_eq!(sm_add_region(m, 0., 0., 0., 1, 0.), SM_ERR_NULL);
        assert_eq!(sm_set_spacing_cb(m, None, null_mut()), SM_ERR_NULL);
        assert_eq!(sm_set_spacing_batch_cb(m, None, null_mut()), SM_ERR_NULL);
        assert_eq!(sm_set_spacing_const(m, 1.0), SM_ERR_NULL);
        assert_eq!(sm_set_param(m, c"rho0".as_ptr(), 2.0), SM_ERR_NULL);
        assert_eq!(sm_get_param(m, c"rho0".as_ptr(), &mut v), SM_ERR_NULL);
        assert_eq!(sm_set_progress_cb(m, None, null_mut()), SM_ERR_NULL);
        assert_eq!(sm_refine(m), SM_ERR_NULL);
        assert_eq!(sm_num_vertices(m), 0);
        assert_eq!(sm_num_tets(m), 0);
        assert_eq!(sm_num_boundary_faces(m), 0);
        assert_eq!(sm_get_vertices(m, buf.as_mut_ptr(), 1), SM_ERR_NULL);
        assert_eq!(sm_get_tets(m, null_mut(), null_mut(), 0), SM_ERR_NULL);
        assert_eq!(
            sm_get_boundary_faces(m, null_mut(), null_mut(), 0),
            SM_ERR_NULL
        );
        assert_eq!(sm_get_quality(m, &mut q), SM_ERR_NULL);
        assert_eq!(sm_write(m, c"x.vtu".as_ptr()), SM_ERR_NULL);
        assert!(sm_stop_reason(m).is_null());
        assert!(text(sm_last_error(m)).contains("NULL"));
    }
}

#[test]
fn input_errors_name_the_culprit() {
    let h = cube();
    let nan = [0.5, f64::NAN, 0.5];
    let ids = [0u32, 1, 9];
    // SAFETY: live handle; pointers valid for the counts given (or NULL where tested).
    unsafe {
        assert_eq!(
            sm_add_vertices(h.0, nan.as_ptr(), 1),
            SM_ERR_INVALID_ARGUMENT
        );
        let e = last_error(&h);
        assert!(
            e.starts_with("sm_add_vertices: ") && e.contains("vertex 8"),
            "{e}"
        );
        assert_eq!(sm_add_vertices(h.0, null(), 2), SM_ERR_NULL);
        assert!(last_error(&h).contains("`xyz` is NULL"));
        assert_eq!(sm_add_vertices(h.0, null(), 0), SM_OK);
        assert_eq!(last_error(&h), "", "success clears the message");
        assert_eq!(
            sm_add_vertices(h.0, nan.as_ptr(), usize::MAX),
            SM_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            sm_add_facet(h.0, ids.as_ptr(), 3, 1),
            SM_ERR_INVALID_ARGUMENT
        );
        assert!(last_error(&h).contains("vertex id 9"));
        assert_eq!(
            sm_add_facet(h.0, ids.as_ptr(), 2, 1),
            SM_ERR_INVALID_ARGUMENT
        );
        assert_eq!(sm_add_facet(h.0, null(), 3, 1), SM_ERR_NULL);
        assert_eq!(
            sm_add_facet_hole(h.0, ids.as_ptr(), 3),
            SM_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            sm_add_facet_hole(h.0, ids.as_ptr(), 2),
            SM_ERR_INVALID_ARGUMENT
        );
        assert_eq!(sm_add_hole(h.0, f64::NAN, 0., 0.), SM_ERR_INVALID_ARGUMENT);
        assert!(last_error(&h).contains("hole 0"));
        assert_eq!(sm_add_hole(h.0, 2., 2., 2.), SM_OK);
        assert_eq!(
            sm_add_region(h.0, 0.5, 0.5, f64::INFINITY, 1, 0.),
            SM_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            sm_add_region(h.0, 0.5, 0.5, 0.5, 1, f64::NAN),
            SM_ERR_INVALID_ARGUMENT
        );
        assert_eq!(sm_add_region(h.0, 0.5, 0.5, 0.5, 1, 0.1), SM_OK);
        let input = (*h.0).state.borrow().mesher.input().clone();
        assert_eq!((input.vertices.len(), input.facets.len()), (8, 6));
        assert_eq!((input.holes.len(), input.regions.len()), (1, 1));
    }
}

#[test]
fn params_by_name() {
    let h = new();
    let mut v = 0.0;
    // SAFETY: live handle; valid strings and out pointers (or NULL where tested).
    unsafe {
        assert_eq!(sm_set_param(h.0, c"rho0".as_ptr(), 1.5), SM_OK);
        assert_eq!(sm_get_param(h.0, c"rho0".as_ptr(), &mut v), SM_OK);
        assert_eq!(v, 1.5);
        assert_eq!(sm_set_param(h.0, c"B".as_ptr(), 3.0), SM_OK);
        assert_eq!(sm_get_param(h.0, c"size_factor".as_ptr(), &mut v), SM_OK);
        assert_eq!(v, 3.0);
        assert_eq!(
            sm_set_param(h.0, c"rho".as_ptr(), 1.5),
            SM_ERR_INVALID_ARGUMENT
        );
        let e = last_error(&h);
        assert!(e.contains("\"rho\"") && e.contains("sigma0"), "{e}");
        assert_eq!(
            sm_set_param(h.0, c"sigma0".as_ptr(), 0.5),
            SM_ERR_INVALID_ARGUMENT
        );
        assert!(last_error(&h).contains("regular"));
        assert_eq!(
            sm_set_param(h.0, c"seed".as_ptr(), f64::NAN),
            SM_ERR_INVALID_ARGUMENT
        );
        assert_eq!(sm_set_param(h.0, null(), 1.0), SM_ERR_NULL);
        assert!(last_error(&h).contains("`name` is NULL"));
        let bad_utf8 = [0xffu8, 0];
        assert_eq!(
            sm_set_param(h.0, bad_utf8.as_ptr().cast(), 1.0),
            SM_ERR_INVALID_ARGUMENT
        );
        assert_eq!(sm_get_param(h.0, c"rho0".as_ptr(), null_mut()), SM_ERR_NULL);
        v = -7.0;
        assert_eq!(
            sm_get_param(h.0, c"nope".as_ptr(), &mut v),
            SM_ERR_INVALID_ARGUMENT
        );
        assert_eq!(v, -7.0, "output untouched on error");
        assert_eq!(sm_set_spacing_const(h.0, 0.0), SM_ERR_INVALID_ARGUMENT);
        assert_eq!(sm_set_spacing_const(h.0, f64::NAN), SM_ERR_INVALID_ARGUMENT);
        assert_eq!(sm_set_spacing_const(h.0, 0.1), SM_OK);
    }
}

#[test]
fn outputs_before_refine() {
    let h = cube();
    let mut buf = [0f64; 24];
    let mut q = sm_quality::default();
    // SAFETY: live handle; buffers of the stated capacity.
    unsafe {
        assert_eq!(sm_num_vertices(h.0), 0);
        assert_eq!(
            sm_get_vertices(h.0, buf.as_mut_ptr(), 8),
            SM_ERR_NOT_REFINED
        );
        assert!(last_error(&h).contains("refine"));
        assert_eq!(
            sm_get_tets(h.0, null_mut(), null_mut(), 0),
            SM_ERR_NOT_REFINED
        );
        assert_eq!(
            sm_get_boundary_faces(h.0, null_mut(), null_mut(), 0),
            SM_ERR_NOT_REFINED
        );
        assert_eq!(sm_get_quality(h.0, &mut q), SM_ERR_NOT_REFINED);
        assert_eq!(sm_write(h.0, c"never.vtu".as_ptr()), SM_ERR_NOT_REFINED);
        assert!(sm_stop_reason(h.0).is_null());
    }
}

#[test]
fn outputs_copy_only_when_everything_fits() {
    let h = new();
    inject(&h);
    // SAFETY: live handle; every buffer holds at least the capacity passed.
    unsafe {
        assert_eq!(
            (
                sm_num_vertices(h.0),
                sm_num_tets(h.0),
                sm_num_boundary_faces(h.0)
            ),
            (5, 2, 3)
        );
        let mut xyz = [-1.0f64; 15];
        assert_eq!(
            sm_get_vertices(h.0, xyz.as_mut_ptr(), 4),
            SM_ERR_BUFFER_TOO_SMALL
        );
        assert!(last_error(&h).contains("capacity 4"));
        assert!(xyz.iter().all(|&x| x == -1.0), "no partial write");
        assert_eq!(sm_get_vertices(h.0, null_mut(), 5), SM_ERR_NULL);
        assert_eq!(sm_get_vertices(h.0, xyz.as_mut_ptr(), 5), SM_OK);
        assert_eq!(&xyz[12..], &[1.0, 1.0, 1.0]);

        let mut tets = [u32::MAX; 8];
        let mut regions = [-1i32; 2];
        assert_eq!(
            sm_get_tets(h.0, tets.as_mut_ptr(), regions.as_mut_ptr(), 1),
            SM_ERR_BUFFER_TOO_SMALL
        );
        assert!(tets.iter().all(|&t| t == u32::MAX) && regions == [-1, -1]);
        assert_eq!(
            sm_get_tets(h.0, null_mut(), regions.as_mut_ptr(), 2),
            SM_ERR_NULL
        );
        assert_eq!(regions, [-1, -1]);
        assert_eq!(sm_get_tets(h.0, tets.as_mut_ptr(), null_mut(), 2), SM_OK);
        assert_eq!(tets, [0, 1, 2, 3, 1, 2, 3, 4]);
        assert_eq!(regions, [-1, -1]);
        assert_eq!(
            sm_get_tets(h.0, tets.as_mut_ptr(), regions.as_mut_ptr(), 2),
            SM_OK
        );
        assert_eq!(regions, [7, 8]);

        let mut tris = [u32::MAX; 9];
        let mut markers = [0i32; 3];
        assert_eq!(
            sm_get_boundary_faces(h.0, tris.as_mut_ptr(), markers.as_mut_ptr(), 2),
            SM_ERR_BUFFER_TOO_SMALL
        );
        assert!(tris.iter().all(|&t| t == u32::MAX));
        assert_eq!(
            sm_get_boundary_faces(h.0, tris.as_mut_ptr(), markers.as_mut_ptr(), 3),
            SM_OK
        );
        assert_eq!(tris, [0, 2, 1, 0, 1, 3, 0, 3, 2]);
        assert_eq!(markers, [1, 2, 3]);

        let mut q = sm_quality::default();
        assert_eq!(sm_get_quality(h.0, null_mut()), SM_ERR_NULL);
        assert_eq!(sm_get_quality(h.0, &mut q), SM_OK);
        assert_eq!((q.n_vertices, q.n_tets, q.n_boundary_faces), (5, 2, 3));
        assert_eq!(
            (q.max_rho, q.tets_below_deg, q.complete),
            (1.5, [0, 1, 2, 3], 1)
        );
        assert_eq!(sm_write(h.0, null()), SM_ERR_NULL);

        // A setter discards the mesh.
        assert_eq!(sm_set_param(h.0, c"seed".as_ptr(), 2.0), SM_OK);
        assert_eq!(sm_num_tets(h.0), 0);
        assert_eq!(sm_get_quality(h.0, &mut q), SM_ERR_NOT_REFINED);
    }
}

unsafe extern "C" fn spacing_nan_at_corner(x: f64, y: f64, z: f64, _: *mut c_void) -> f64 {
    if (x, y, z) == (1.0, 1.0, 1.0) {
        f64::NAN
    } else {
        0.25
    }
}

unsafe extern "C" fn batch_zero(n: usize, _xyz: *const f64, out: *mut f64, _: *mut c_void) {
    // SAFETY: the library passes `n` writable doubles.
    unsafe { std::slice::from_raw_parts_mut(out, n) }.fill(0.0);
}

unsafe extern "C" fn batch_silent(_: usize, _: *const f64, _: *mut f64, _: *mut c_void) {}

unsafe extern "C" fn cancel(fraction: f64, n: usize, seen: *mut c_void) -> i32 {
    // SAFETY: the test passes a pointer to its record.
    unsafe { (*seen.cast::<Vec<(f64, usize)>>()).push((fraction, n)) };
    1
}

#[test]
fn bad_spacing_from_callbacks_fails_refine_naming_the_point() {
    let h = cube();
    // SAFETY: live handle; callbacks with the right signatures, no user data needed.
    unsafe {
        assert_eq!(
            sm_set_spacing_cb(h.0, Some(spacing_nan_at_corner), null_mut()),
            SM_OK
        );
        assert_eq!(sm_refine(h.0), SM_ERR_SPACING);
        let e = last_error(&h);
        assert!(e.contains("NaN") && e.contains("(1, 1, 1)"), "{e}");
        assert_eq!(sm_num_tets(h.0), 0);

        assert_eq!(
            sm_set_spacing_batch_cb(h.0, Some(batch_zero), null_mut()),
            SM_OK
        );
        assert_eq!(sm_refine(h.0), SM_ERR_SPACING);
        assert!(last_error(&h).contains("returned 0 at (0, 0, 0)"));

        assert_eq!(
            sm_set_spacing_batch_cb(h.0, Some(batch_silent), null_mut()),
            SM_OK
        );
        assert_eq!(sm_refine(h.0), SM_ERR_SPACING);
        assert!(last_error(&h).contains("NaN"));

        // Constant spacing replaces the callback; NULL callback = automatic.
        assert_eq!(sm_set_spacing_const(h.0, 0.3), SM_OK);
        assert!((*h.0).state.borrow().spacing_cb.is_none());
        assert_eq!(sm_set_spacing_cb(h.0, None, null_mut()), SM_OK);
        assert!(matches!(
            (*h.0).state.borrow().mesher.spacing(),
            crate::api::SpacingChoice::Automatic
        ));
    }
}

#[test]
fn progress_callback_cancels() {
    let h = cube();
    let mut seen: Vec<(f64, usize)> = Vec::new();
    // SAFETY: live handle; `seen` outlives the refine that uses it.
    unsafe {
        let ud = (&mut seen as *mut Vec<(f64, usize)>).cast();
        assert_eq!(sm_set_progress_cb(h.0, Some(cancel), ud), SM_OK);
        assert_eq!(sm_refine(h.0), SM_ERR_CANCELLED);
        assert!(last_error(&h).contains("cancelled"));
        assert_eq!(sm_set_progress_cb(h.0, None, null_mut()), SM_OK);
    }
    assert_eq!(seen, [(0.0, 8)]);
}

thread_local! {
    /// What `reenter` saw: (sm_add_hole status, sm_num_vertices, sm_last_error).
    static SEEN: std::cell::RefCell<Vec<(sm_status, usize, String)>> = const {
        std::cell::RefCell::new(Vec::new())
    };
}

/// Calls functions on its own handle from inside a callback (no asserts: a panic may not leave
/// an `extern "C"` function), destroying it on the first call.
unsafe extern "C" fn reenter(_x: f64, _y: f64, _z: f64, m: *mut c_void) -> f64 {
    let m = m.cast::<sm_mesher>();
    // SAFETY: the test passes the live handle that is running this callback.
    let seen = unsafe {
        (
            sm_add_hole(m, 5.0, 5.0, 5.0),
            sm_num_vertices(m),
            text(sm_last_error(m)),
        )
    };
    let first = SEEN.with_borrow_mut(|s| {
        s.push(seen);
        s.len() == 1
    });
    if first {
        // SAFETY: as above; the library refuses (the handle is busy) and poisons it instead.
        unsafe { sm_destroy(m) };
    }
    0.5
}

#[test]
fn reentry_from_a_callback_is_refused_not_undefined() {
    let h = cube();
    // SAFETY: live handle passed as its own user data.
    unsafe {
        assert_eq!(sm_set_spacing_cb(h.0, Some(reenter), h.0.cast()), SM_OK);
        assert_eq!(sm_refine(h.0), SM_ERR_POISONED);
        assert_eq!(sm_add_hole(h.0, 5.0, 5.0, 5.0), SM_ERR_POISONED);
        assert!(last_error(&h).contains("sm_destroy: called from a callback"));
    }
    let seen = SEEN.with_borrow(|s| s.clone());
    assert!(!seen.is_empty());
    let (status, n, msg) = &seen[0];
    assert_eq!((*status, *n), (SM_ERR_BUSY, 0));
    assert!(msg.contains("callbacks must not call"), "{msg}");
    assert!(seen[1..].iter().all(|s| s.0 == SM_ERR_POISONED));
}

#[test]
fn a_panic_poisons_the_handle() {
    let h = cube();
    // SAFETY: live handle, not borrowed elsewhere.
    unsafe { &*h.0 }
        .state
        .borrow_mut()
        .mesher
        .set_spacing_fn(|_| panic!("boom in spacing"));
    let mut q = sm_quality::default();
    // SAFETY: live handle.
    unsafe {
        assert_eq!(sm_refine(h.0), SM_ERR_PANIC);
        let e = last_error(&h);
        assert!(
            e.contains("boom in spacing") && e.contains("poisoned"),
            "{e}"
        );
        assert_eq!(sm_refine(h.0), SM_ERR_POISONED);
        assert_eq!(sm_set_param(h.0, c"rho0".as_ptr(), 2.0), SM_ERR_POISONED);
        assert_eq!(sm_get_quality(h.0, &mut q), SM_ERR_POISONED);
        assert_eq!(sm_num_vertices(h.0), 0);
        assert!(last_error(&h).contains("boom"), "the panic message stays");
    }
}

/// Waits on `refine::mesh`: the cube through the C ABI, volumes adding up to 1.
#[test]
fn cube_through_the_c_abi() {
    let h = cube();
    // SAFETY: live handle; buffers sized from the counts.
    unsafe {
        assert_eq!(sm_set_spacing_const(h.0, 0.3), SM_OK);
        let s = sm_refine(h.0);
        if s == SM_ERR_INTERNAL && last_error(&h).contains("not implemented yet") {
            eprintln!("skipped: refine::mesh is not implemented yet");
            return;
        }
        assert_eq!(s, SM_OK, "{}", last_error(&h));
        let (nv, nt) = (sm_num_vertices(h.0), sm_num_tets(h.0));
        assert!(nv >= 8 && nt > 0);
        let mut xyz = vec![0.0; 3 * nv];
        let mut tets = vec![0u32; 4 * nt];
        assert_eq!(sm_get_vertices(h.0, xyz.as_mut_ptr(), nv), SM_OK);
        assert_eq!(sm_get_tets(h.0, tets.as_mut_ptr(), null_mut(), nt), SM_OK);
        let p = |i: u32| DVec3::from_slice(&xyz[3 * i as usize..]);
        let volume: f64 = tets
            .chunks_exact(4)
            .map(|t| {
                (p(t[1]) - p(t[0]))
                    .cross(p(t[2]) - p(t[0]))
                    .dot(p(t[3]) - p(t[0]))
                    / 6.0
            })
            .sum();
        assert!((volume - 1.0).abs() < 1e-9, "{volume}");
        // The binary forms: a gmsh 4.1 binary .msh and a .vtu of appended raw arrays.
        let dir = std::env::temp_dir().join(format!("sm-ffi-binary-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (name, marker) in [
            ("cube.msh", &b"$MeshFormat\n4.1 1 8\n"[..]),
            ("cube.vtu", &b"<AppendedData encoding=\"raw\">"[..]),
        ] {
            let path = dir.join(name);
            let c_path = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
            assert_eq!(
                sm_write_binary(h.0, c_path.as_ptr()),
                SM_OK,
                "{}",
                last_error(&h)
            );
            let bytes = std::fs::read(&path).unwrap();
            assert!(
                bytes.windows(marker.len()).any(|w| w == marker),
                "{name} is not in its binary form"
            );
        }
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// `sm_set_marker_size`: `h` is checked at once, the marker at `sm_refine` (named, with the
/// input's markers); a valid one refines the faces of that marker: with a constant spacing of
/// 0.5 and marker 3 (y = 0) capped at 0.1, that face gets many times the triangles of the
/// opposite one (marker 4, y = 1).
#[test]
fn marker_size_through_the_c_abi() {
    // SAFETY: a NULL handle is allowed; the others are live, buffers sized from the counts.
    unsafe {
        assert_eq!(sm_set_marker_size(null_mut(), 1, 0.1), SM_ERR_NULL);
        let h = cube();
        assert_eq!(sm_set_marker_size(h.0, 3, 0.0), SM_ERR_INVALID_ARGUMENT);
        assert!(last_error(&h).contains("marker 3"), "{}", last_error(&h));
        assert_eq!(
            sm_set_marker_size(h.0, 3, f64::INFINITY),
            SM_ERR_INVALID_ARGUMENT
        );
        assert_eq!(sm_set_marker_size(h.0, 9, 0.1), SM_OK);
        assert_eq!(sm_refine(h.0), SM_ERR_INVALID_INPUT);
        let e = last_error(&h);
        assert!(
            e.contains("marker 9") && e.contains("its markers: 1-6"),
            "{e}"
        );

        let h = cube();
        assert_eq!(sm_set_spacing_const(h.0, 0.5), SM_OK);
        assert_eq!(sm_set_marker_size(h.0, 3, 0.1), SM_OK);
        assert_eq!(sm_refine(h.0), SM_OK, "{}", last_error(&h));
        let n = sm_num_boundary_faces(h.0);
        let mut tris = vec![0u32; 3 * n];
        let mut markers = vec![0i32; n];
        assert_eq!(
            sm_get_boundary_faces(h.0, tris.as_mut_ptr(), markers.as_mut_ptr(), n),
            SM_OK
        );
        let count = |m: i32| markers.iter().filter(|&&k| k == m).count();
        assert!(count(3) > 10 * count(4), "{} vs {}", count(3), count(4));
    }
}

/// A size field on a background mesh of the cube (six tets around its diagonal), varying 6x
/// along x: the tets near x = 0 come out smaller than those near x = 1; a bad value is named.
#[test]
fn size_field_through_the_c_abi() {
    let h = cube();
    let corners: Vec<f64> = (0..8)
        .flat_map(|i| [i & 1, (i >> 1) & 1, (i >> 2) & 1].map(f64::from))
        .collect();
    let tets: [u32; 24] = [
        0, 1, 3, 7, 0, 3, 2, 7, 0, 2, 6, 7, 0, 6, 4, 7, 0, 4, 5, 7, 0, 5, 1, 7,
    ];
    let field = |x: f64| 0.05 + 0.25 * x;
    let values: Vec<f64> = corners.chunks_exact(3).map(|p| field(p[0])).collect();
    // SAFETY: live handle; the arrays hold the counts passed.
    unsafe {
        let mut bad = values.clone();
        bad[5] = 0.0;
        let s = sm_set_spacing_mesh(h.0, corners.as_ptr(), 8, tets.as_ptr(), 6, bad.as_ptr());
        assert_eq!(s, SM_ERR_INVALID_ARGUMENT);
        assert!(last_error(&h).contains('6'), "{}", last_error(&h));
        let s = sm_set_spacing_mesh(h.0, corners.as_ptr(), 8, tets.as_ptr(), 6, values.as_ptr());
        assert_eq!(s, SM_OK, "{}", last_error(&h));
        assert_eq!(sm_refine(h.0), SM_OK, "{}", last_error(&h));
        let (nv, nt) = (sm_num_vertices(h.0), sm_num_tets(h.0));
        let mut xyz = vec![0.0; 3 * nv];
        let mut t = vec![0u32; 4 * nt];
        assert_eq!(sm_get_vertices(h.0, xyz.as_mut_ptr(), nv), SM_OK);
        assert_eq!(sm_get_tets(h.0, t.as_mut_ptr(), null_mut(), nt), SM_OK);
        let p = |i: u32| DVec3::from_slice(&xyz[3 * i as usize..]);
        // Mean edge length of the tets whose centroid lies in each end slab.
        let mean_edge = |lo: f64, hi: f64| {
            let (mut sum, mut n) = (0.0, 0);
            for tet in t.chunks_exact(4) {
                let c = tet.iter().map(|&v| p(v)).sum::<DVec3>() / 4.0;
                if c.x >= lo && c.x < hi {
                    for (a, b) in [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
                        sum += (p(tet[a]) - p(tet[b])).length();
                        n += 1;
                    }
                }
            }
            sum / n as f64
        };
        let (near, far) = (mean_edge(0.0, 0.2), mean_edge(0.8, 1.0));
        assert!(
            far > 2.0 * near,
            "edges near x = 0: {near}, near x = 1: {far}"
        );
    }
}

/// Two regions through the C ABI: the cube split by the facet x = 0.5 (two region seeds), each
/// region's figures and the interface area from `sm_get_regions`.
#[test]
fn regions_through_the_c_abi() {
    let h = new();
    let mut xyz = CUBE_XYZ.to_vec();
    // The mid-plane's corners: ids 8-11.
    for (y, z) in [(0., 0.), (1., 0.), (1., 1.), (0., 1.)] {
        xyz.extend([0.5, y, z]);
    }
    // SAFETY: live handle, arrays of the stated sizes, buffers sized from the counts.
    unsafe {
        assert_eq!(sm_add_vertices(h.0, xyz.as_ptr(), 12), SM_OK);
        // x = 0 and x = 1 sides whole; the four others split at x = 0.5.
        let faces: [&[u32]; 11] = [
            &[0, 4, 6, 2],
            &[1, 3, 7, 5],
            &[8, 9, 10, 11],
            &[0, 8, 11, 4],
            &[8, 1, 5, 11],
            &[2, 6, 10, 9],
            &[9, 10, 7, 3],
            &[0, 2, 9, 8],
            &[8, 9, 3, 1],
            &[4, 11, 10, 6],
            &[11, 5, 7, 10],
        ];
        for (k, f) in faces.iter().enumerate() {
            assert_eq!(sm_add_facet(h.0, f.as_ptr(), f.len(), k as i32 + 1), SM_OK);
        }
        assert_eq!(sm_add_region(h.0, 0.25, 0.5, 0.5, 7, -1.0), SM_OK);
        assert_eq!(sm_add_region(h.0, 0.75, 0.5, 0.5, 9, -1.0), SM_OK);
        assert_eq!(sm_num_regions(h.0), 0, "before refining");
        assert_eq!(sm_set_spacing_const(h.0, 0.3), SM_OK);
        assert_eq!(sm_refine(h.0), SM_OK, "{}", last_error(&h));
        assert_eq!(sm_num_regions(h.0), 2);
        let mut regions = [sm_region::default(); 2];
        assert_eq!(
            sm_get_regions(h.0, regions.as_mut_ptr(), 1, null_mut(), null_mut()),
            SM_ERR_BUFFER_TOO_SMALL
        );
        let (mut area, mut input_area) = (0.0, 0.0);
        assert_eq!(
            sm_get_regions(h.0, regions.as_mut_ptr(), 2, &mut area, &mut input_area),
            SM_OK
        );
        assert_eq!([regions[0].attribute, regions[1].attribute], [7, 9]);
        let nt = sm_num_tets(h.0);
        assert_eq!(regions[0].tets + regions[1].tets, nt);
        for r in regions {
            assert!((r.volume - 0.5).abs() < 1e-9 && (r.input_volume - 0.5).abs() < 1e-12);
            assert!(r.relative_volume_difference.abs() < 1e-9);
        }
        assert!((area - 1.0).abs() < 1e-9 && (input_area - 1.0).abs() < 1e-12);
    }
}

/// Ten-node tets through the C ABI: refused before `"order"` 2, then corners as `sm_get_tets`
/// gives them and (keep mode: planar facets) every edge node at its edge's midpoint.
#[test]
fn ten_node_tets_through_the_c_abi() {
    let h = cube();
    let order = std::ffi::CString::new("order").unwrap();
    // SAFETY: live handle; buffers sized from the counts.
    unsafe {
        assert_eq!(sm_set_spacing_const(h.0, 0.4), SM_OK);
        assert_eq!(sm_refine(h.0), SM_OK, "{}", last_error(&h));
        let nt = sm_num_tets(h.0);
        assert_eq!(sm_num_nodes(h.0), sm_num_vertices(h.0));
        let mut tets10 = vec![0u32; 10 * nt];
        assert_eq!(
            sm_get_tets10(h.0, tets10.as_mut_ptr(), nt),
            SM_ERR_NOT_REFINED
        );
        assert!(last_error(&h).contains("order"), "{}", last_error(&h));

        assert_eq!(sm_set_param(h.0, order.as_ptr(), 2.0), SM_OK);
        assert_eq!(sm_refine(h.0), SM_OK, "{}", last_error(&h));
        let (nv, nt, nn) = (sm_num_vertices(h.0), sm_num_tets(h.0), sm_num_nodes(h.0));
        assert!(nn > nv);
        let mut xyz = vec![0.0; 3 * nn];
        let mut tets = vec![0u32; 4 * nt];
        let mut tets10 = vec![0u32; 10 * nt];
        assert_eq!(sm_get_nodes(h.0, xyz.as_mut_ptr(), nn), SM_OK);
        assert_eq!(sm_get_tets(h.0, tets.as_mut_ptr(), null_mut(), nt), SM_OK);
        assert_eq!(
            sm_get_tets10(h.0, tets10.as_mut_ptr(), nt - 1),
            SM_ERR_BUFFER_TOO_SMALL
        );
        assert_eq!(sm_get_tets10(h.0, tets10.as_mut_ptr(), nt), SM_OK);
        let p = |i: u32| DVec3::from_slice(&xyz[3 * i as usize..]);
        let mut mids = std::collections::HashSet::new();
        for (t4, t10) in tets.chunks_exact(4).zip(tets10.chunks_exact(10)) {
            assert_eq!(t4, &t10[..4]);
            for (e, &(i, j)) in crate::mesh::TET_EDGES.iter().enumerate() {
                let node = t10[4 + e];
                assert!((node as usize) >= nv && (node as usize) < nn);
                assert!(p(node).distance((p(t4[i]) + p(t4[j])) * 0.5) < 1e-12);
                mids.insert(node);
            }
        }
        assert_eq!(mids.len(), nn - nv, "every node belongs to an edge");
    }
}

/// An existing mesh through the C ABI: the cube meshed without improvement, handed to a fresh
/// mesher whose refine removes its slivers: the volume and the boundary stay, no tet is flat,
/// and a bad id is named.
#[test]
fn existing_mesh_through_the_c_abi() {
    let h = cube();
    let improve = std::ffi::CString::new("improve").unwrap();
    // SAFETY: live handles; buffers sized from the counts.
    unsafe {
        assert_eq!(sm_set_spacing_const(h.0, 0.3), SM_OK);
        assert_eq!(sm_set_param(h.0, improve.as_ptr(), 0.0), SM_OK);
        assert_eq!(sm_refine(h.0), SM_OK, "{}", last_error(&h));
        let (nv, nt, nf) = (
            sm_num_vertices(h.0),
            sm_num_tets(h.0),
            sm_num_boundary_faces(h.0),
        );
        let mut xyz = vec![0.0; 3 * nv];
        let mut tets = vec![0u32; 4 * nt];
        let mut tris = vec![0u32; 3 * nf];
        let mut markers = vec![0i32; nf];
        assert_eq!(sm_get_vertices(h.0, xyz.as_mut_ptr(), nv), SM_OK);
        assert_eq!(sm_get_tets(h.0, tets.as_mut_ptr(), null_mut(), nt), SM_OK);
        assert_eq!(
            sm_get_boundary_faces(h.0, tris.as_mut_ptr(), markers.as_mut_ptr(), nf),
            SM_OK
        );

        let e = new();
        let mut bad = tets.clone();
        bad[1] = nv as u32;
        assert_eq!(
            sm_set_existing_mesh(
                e.0,
                xyz.as_ptr(),
                nv,
                bad.as_ptr(),
                null(),
                nt,
                tris.as_ptr(),
                markers.as_ptr(),
                nf
            ),
            SM_ERR_INVALID_ARGUMENT
        );
        assert!(last_error(&e).contains("tet 0"), "{}", last_error(&e));
        assert_eq!(
            sm_set_existing_mesh(
                e.0,
                xyz.as_ptr(),
                nv,
                tets.as_ptr(),
                null(),
                nt,
                tris.as_ptr(),
                markers.as_ptr(),
                nf
            ),
            SM_OK
        );
        assert_eq!(sm_refine(e.0), SM_OK, "{}", last_error(&e));
        let (nv2, nt2) = (sm_num_vertices(e.0), sm_num_tets(e.0));
        let mut xyz2 = vec![0.0; 3 * nv2];
        let mut tets2 = vec![0u32; 4 * nt2];
        assert_eq!(sm_get_vertices(e.0, xyz2.as_mut_ptr(), nv2), SM_OK);
        assert_eq!(sm_get_tets(e.0, tets2.as_mut_ptr(), null_mut(), nt2), SM_OK);
        let p = |i: u32| DVec3::from_slice(&xyz2[3 * i as usize..]);
        let volumes: Vec<f64> = tets2
            .chunks_exact(4)
            .map(|t| {
                (p(t[1]) - p(t[0]))
                    .cross(p(t[2]) - p(t[0]))
                    .dot(p(t[3]) - p(t[0]))
                    / 6.0
            })
            .collect();
        assert!(volumes.iter().all(|&v| v > 0.0));
        let volume: f64 = volumes.iter().sum();
        assert!((volume - 1.0).abs() < 1e-9, "{volume}");
        let mut q = std::mem::zeroed::<sm_quality>();
        assert_eq!(sm_get_quality(e.0, &mut q), SM_OK);
        assert!(q.min_dihedral_deg > 15.0, "{}", q.min_dihedral_deg);
    }
}
