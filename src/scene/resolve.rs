//! Filling in derived material values (MODEL.md §11): E, f't, f_y, f_ult, G_f0, G_f, COD_c and
//! the default Δmax in tension, each recorded with its source in [`Scene::derived`]. Inputs
//! are checked before any correlation sees them, so a bad value is named as the user wrote it.

use super::validate::invalid;
use super::*;
use crate::material::concrete::{self as cc, Derived};
use crate::model::damage::ConcreteLaw;

fn positive_opt(key: &str, v: Option<f64>) -> Result<(), SceneError> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0) => {
            Err(invalid(key, x, "must be a finite number greater than zero"))
        }
        _ => Ok(()),
    }
}

impl Scene {
    /// Fill every derived value (see the module docs). Called by [`Scene::from_toml_str`]
    /// before [`Scene::validate`].
    pub fn resolve(&mut self) -> Result<(), SceneError> {
        self.derived.clear();
        let rho = self.material.rho;
        let Some(c) = self.concrete.clone() else {
            let Some(e) = self.material.e else {
                return Err(invalid(
                    "material.E",
                    "(missing)",
                    "give Young's modulus E in Pa, or a [concrete] section to derive it from f'c and rho (ACI 318-14)",
                ));
            };
            self.record("E", e, "scene");
            for (gi, g) in self.groups.iter().enumerate() {
                if let Some(l) = &g.load {
                    if l.displacement.is_none() {
                        return Err(invalid(
                            format!("groups[{gi}].load.displacement"),
                            "(missing)",
                            "give the displacement at the end of the ramp in m (it defaults to 1.5·COD_c only in a scene with [concrete])",
                        ));
                    }
                }
            }
            return Ok(());
        };
        // Raw inputs first, as written.
        for (key, v) in [
            ("concrete.fc", c.fc),
            ("concrete.ft", c.ft),
            ("concrete.fy", c.fy),
            ("concrete.fult", c.fult),
            ("concrete.Gf", c.gf),
            ("concrete.Gf0", c.gf0),
            ("concrete.max_aggregate", c.max_aggregate),
            ("material.E", self.material.e),
        ] {
            positive_opt(key, v)?;
        }
        if !(rho.is_finite() && rho > 0.0) {
            return Err(invalid(
                "material.rho",
                rho,
                "must be a finite number greater than zero",
            ));
        }
        let preset = c.preset.map(|p| (p, p.values()));
        let preset_name = |p: cc::Preset| {
            format!(
                "preset {}",
                serde_json::to_value(p)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_string))
                    .unwrap_or_default()
            )
        };
        let (fc, fc_src) = match (c.fc, preset) {
            (Some(v), _) => (v, "scene".to_string()),
            (None, Some((p, (fc, _, _)))) => (fc, preset_name(p)),
            (None, None) => {
                return Err(invalid(
                    "concrete.fc",
                    "(missing)",
                    "give the compressive strength f'c in Pa, or concrete.preset",
                ))
            }
        };
        self.record("fc", fc, &fc_src);
        let e = match self.material.e {
            Some(e) => {
                self.record("E", e, "scene");
                e
            }
            None => {
                let e = cc::aci_youngs_modulus(fc, rho);
                self.record(
                    "E",
                    e,
                    "ACI 318-14: E = 33·rho^1.5·sqrt(f'c) [psi, lb/ft3] (5.2)",
                );
                self.material.e = Some(e);
                e
            }
        };
        let ft = match (c.ft, preset) {
            (Some(v), _) => {
                self.record("ft", v, "scene");
                v
            }
            (None, Some((p, (_, _, Some(ft))))) => {
                self.record("ft", ft, &preset_name(p));
                ft
            }
            _ => {
                let v = cc::aci_tensile_strength(fc);
                self.record("ft", v, "ACI 318-92: f't = 6·sqrt(f'c) [psi] (5.1)");
                v
            }
        };
        let fy = c.fy.unwrap_or(5.0 / 6.0 * fc);
        self.record(
            "fy",
            fy,
            if c.fy.is_some() {
                "scene"
            } else {
                "(5/6)·f'c"
            },
        );
        let fult = c.fult.unwrap_or(fc);
        self.record("fult", fult, if c.fult.is_some() { "scene" } else { "f'c" });
        let gf = match c.gf {
            Some(v) => {
                self.record("Gf", v, "scene");
                v
            }
            None => {
                let gf0 = match c.gf0 {
                    Some(v) => {
                        self.record("Gf0", v, "scene");
                        v
                    }
                    None => {
                        let (dmax, src) = match (c.max_aggregate, preset) {
                            (Some(d), _) => (d, "scene".to_string()),
                            (None, Some((p, (_, d, _)))) => (d, preset_name(p)),
                            (None, None) => {
                                return Err(invalid(
                                    "concrete.Gf",
                                    "(missing)",
                                    "give the fracture energy Gf in N/m, or Gf0, or max_aggregate (m) for the CEB-FIP 1990 correlation",
                                ))
                            }
                        };
                        self.record("max_aggregate", dmax, &src);
                        let Some(gf0) = cc::base_fracture_energy(dmax) else {
                            return Err(invalid(
                                "concrete.max_aggregate",
                                dmax,
                                "one of 0.008, 0.016, 0.032 m (CEB-FIP 1990) or 0.019 m (the source); for another size give concrete.Gf0 or concrete.Gf",
                            ));
                        };
                        self.record("Gf0", gf0, "CEB-FIP 1990 table for max_aggregate");
                        gf0
                    }
                };
                let v = cc::ceb_fip_fracture_energy(gf0, fc);
                self.record(
                    "Gf",
                    v,
                    "CEB-FIP 1990: Gf = Gf0·((f'c + 8 MPa)/10 MPa)^0.7 (5.3)",
                );
                v
            }
        };
        // Ranges of the law's parameters.
        let frac = |key: &str, v: f64, lo_open: bool| -> Result<(), SceneError> {
            let ok = v.is_finite() && v < 1.0 && if lo_open { v > 0.0 } else { v >= 0.0 };
            if ok {
                Ok(())
            } else {
                Err(invalid(
                    key,
                    v,
                    if lo_open {
                        "must satisfy 0 < value < 1"
                    } else {
                        "must satisfy 0 <= value < 1"
                    },
                ))
            }
        };
        frac("concrete.alpha", c.alpha, true)?;
        frac("concrete.gamma", c.gamma, true)?;
        frac("concrete.wt_cr", c.wt_cr, false)?;
        if !(c.wc_max.is_finite() && (0.0..=1.0).contains(&c.wc_max)) {
            return Err(invalid(
                "concrete.wc_max",
                c.wc_max,
                "must satisfy 0 <= value <= 1",
            ));
        }
        if !(c.eps_ult.is_finite() && c.eps_ult > 0.0 && c.eps_ult < 0.1) {
            return Err(invalid(
                "concrete.eps_ult",
                c.eps_ult,
                "must satisfy 0 < eps_ult < 0.1",
            ));
        }
        if ft >= fc {
            return Err(invalid(
                "concrete.ft",
                ft,
                format!("must be below f'c = {fc:e} Pa"),
            ));
        }
        if fy > fult {
            return Err(invalid(
                "concrete.fy",
                fy,
                format!("must not exceed f_ult = {fult:e} Pa"),
            ));
        }
        let cod_c = cc::critical_crack_opening(gf, ft, c.alpha, c.gamma);
        self.record("COD_c", cod_c, "2·Gf/(f't·(alpha+gamma)) (5.4)");
        // The crack opening of a particle at initiation, 2·L0·f't/E (4.13): the softening law
        // needs room beyond it.
        let l0 = self.discretisation.spacing;
        if !(c.crack_band.is_finite() && c.crack_band > 0.0 && c.crack_band <= 10.0) {
            return Err(invalid(
                "concrete.crack_band",
                c.crack_band,
                "must satisfy 0 < crack_band <= 10 (a multiple of the lattice spacing)",
            ));
        }
        let cod_el = c.crack_band * l0 * ft / e;
        if l0.is_finite() && l0 > 0.0 && cod_c <= cod_el {
            let gf_min = cod_el * ft * (c.alpha + c.gamma) / 2.0;
            return Err(invalid(
                "concrete.Gf",
                format!("{gf:.4} N/m"),
                format!(
                    "gives COD_c = {cod_c:.3e} m, not above the elastic crack opening crack_band·L0·f't/E = {cod_el:.3e} m of this lattice spacing; Gf must exceed {gf_min:.4} N/m, or use a smaller discretisation.spacing"
                ),
            ));
        }
        for gi in 0..self.groups.len() {
            if let Some(l) = &mut self.groups[gi].load {
                if l.displacement.is_none() {
                    l.displacement = Some(1.5 * cod_c);
                    let key = format!("groups.{}.load.displacement", self.groups[gi].name);
                    self.record(
                        &key,
                        1.5 * cod_c,
                        "1.5·COD_c (tension default, MODEL.md §10)",
                    );
                }
            }
        }
        Ok(())
    }

    fn record(&mut self, key: &str, value: f64, source: &str) {
        self.derived.push(Derived {
            key: key.into(),
            value,
            source: source.into(),
        });
    }

    /// A derived value by key (after [`Scene::resolve`]).
    pub fn derived_value(&self, key: &str) -> Option<f64> {
        self.derived.iter().find(|d| d.key == key).map(|d| d.value)
    }

    /// The concrete law of a resolved scene, if it has `[concrete]`.
    pub fn concrete_law(&self) -> Option<ConcreteLaw> {
        let c = self.concrete.as_ref()?;
        let get = |k: &str| self.derived_value(k).unwrap_or(f64::NAN);
        let (ft, gf) = (get("ft"), get("Gf"));
        let cod_c = cc::critical_crack_opening(gf, ft, c.alpha, c.gamma);
        Some(ConcreteLaw {
            e: self.material.youngs_modulus(),
            nu: self.material.nu,
            plane: self.material.plane,
            fc: get("fc"),
            ft,
            fy: get("fy"),
            fult: get("fult"),
            gf,
            cod_c,
            cod_1: c.alpha * cod_c,
            gamma: c.gamma,
            eps_ult: c.eps_ult,
            wt_cr: c.wt_cr,
            wc_max: c.wc_max,
            initiation: c.initiation,
            crack_opening: c.crack_opening,
            tensile_damage: c.tensile_damage,
            compressive_damage: c.compressive_damage,
            plasticity: c.plasticity,
            crack_band: c.crack_band * self.discretisation.spacing,
        })
    }
}
