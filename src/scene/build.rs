//! Scene building: the `ObjectDesc` tree → [`Scene`] (meshes loaded and transformed, BVH built,
//! BSDFs, emitters, media, sensor and integrator instantiated). Objects referenced twice
//! (`<ref>`) are built once and shared by index.

use super::desc::{ObjectDesc, PluginKind};
use super::resolver::FileResolver;
use super::world::{Scene, SceneEmitter};
use super::xml::ParsedScene;
use super::{Error, Result};
use crate::bsdf::Bsdf;
use crate::emitter::Emitter;
use crate::integrator::{self, Integrator, IntegratorDesc};
use crate::math::{Aabb, Vec3};
use crate::medium::Homogeneous;
use crate::sensor::Sensor;
use crate::shape::accel::Accel;
use crate::shape::{Geometry, Shape};
use crate::texture::Texture;
use std::collections::HashMap;
use std::path::Path;
use std::rc::Rc;

/// Parse and build a scene file.
pub fn load_scene(path: &Path, defines: &[(String, String)]) -> Result<Scene> {
    let parsed = super::xml::parse_file(path, defines)?;
    build_scene(&parsed)
}

struct Builder<'a> {
    resolver: &'a FileResolver,
    shapes: Vec<Shape>,
    bsdfs: Vec<Bsdf>,
    bsdf_ids: HashMap<*const ObjectDesc, u32>,
    media: Vec<Homogeneous>,
    medium_ids: HashMap<*const ObjectDesc, u32>,
    emitters: Vec<SceneEmitter>,
    environment: Option<(u32, ObjectPos)>,
    default_bsdf: Option<u32>,
    black_bsdf: Option<u32>,
    /// An irradiance meter nested in a shape, with its position.
    meter: Option<(Sensor, ObjectPos)>,
}

type ObjectPos = super::SrcPos;

pub fn build_scene(parsed: &ParsedScene) -> Result<Scene> {
    let root = &parsed.root;
    let mut b = Builder {
        resolver: &parsed.resolver,
        shapes: Vec::new(),
        bsdfs: Vec::new(),
        bsdf_ids: HashMap::new(),
        media: Vec::new(),
        medium_ids: HashMap::new(),
        emitters: Vec::new(),
        environment: None,
        default_bsdf: None,
        black_bsdf: None,
        meter: None,
    };
    let mut integrator: Option<(IntegratorDesc, ObjectPos)> = None;
    let mut sensor: Option<Sensor> = None;
    let mut sensor_pos: Option<ObjectPos> = None;
    for (_, obj) in root.props.objects() {
        match obj.kind {
            PluginKind::Integrator => {
                if let Some((_, first)) = &integrator {
                    return Err(Error::at(
                        &obj.pos,
                        format!("a scene has at most one integrator (the first is at {})", first),
                    ));
                }
                integrator = Some((integrator::parse(&obj)?, obj.pos.clone()));
            }
            PluginKind::Sensor => {
                if let Some(first) = &sensor_pos {
                    return Err(Error::at(
                        &obj.pos,
                        format!("only one sensor is supported (the first is at {})", first),
                    ));
                }
                if obj.plugin != "perspective" {
                    return Err(Error::at(
                        &obj.pos,
                        format!("sensor \"{}\" is not supported at the top level (supported: perspective)", obj.plugin),
                    ));
                }
                sensor = Some(Sensor::from_desc(&obj, b.resolver)?);
                sensor_pos = Some(obj.pos.clone());
            }
            PluginKind::Shape => b.shape(&obj)?,
            PluginKind::Emitter => b.emitter(&obj)?,
            PluginKind::Bsdf => {
                b.bsdf(&obj)?;
            }
            PluginKind::Medium => {
                b.medium(&obj)?;
            }
            PluginKind::Texture => {
                Texture::from_arg(&super::desc::TexArg::Texture(obj.clone()), b.resolver)?;
            }
            PluginKind::Phase => {
                crate::medium::Phase::from_desc(&obj)?;
            }
            PluginKind::Film | PluginKind::RFilter | PluginKind::Sampler | PluginKind::Scene => {
                return Err(Error::at(
                    &obj.pos,
                    format!("a <{}> must be nested in a <sensor> (or film), not in the scene", obj.kind.tag()),
                ));
            }
        }
    }
    root.props.finish()?;
    let mut sensor = match (sensor, b.meter.take()) {
        (Some(s), None) => s,
        (None, Some((m, _))) => m,
        (Some(_), Some((_, pos))) => {
            return Err(Error::at(
                &pos,
                format!(
                    "only one sensor is supported (a perspective sensor is at {})",
                    sensor_pos.map(|p| p.to_string()).unwrap_or_default()
                ),
            ));
        }
        (None, None) => {
            return Err(Error::at(
                &root.pos,
                "the scene has no <sensor> (a perspective camera or an irradiancemeter is needed to render)",
            ));
        }
    };
    let sensor_medium = match sensor.medium_ref.take() {
        Some(m) => Some(b.medium(&m)?),
        None => None,
    };
    let integrator = integrator.map(|i| i.0).unwrap_or_default();

    let mut bounds = Aabb::EMPTY;
    for s in &b.shapes {
        bounds = bounds.union(&s.bounds());
    }
    let (center, radius) = if bounds.is_empty() {
        (Vec3::ZERO, 1.0)
    } else {
        let c = bounds.center();
        (c, ((bounds.max - c).length() * (1.0 + crate::interaction::RAY_EPSILON)).max(crate::interaction::RAY_EPSILON))
    };
    for e in &mut b.emitters {
        if let SceneEmitter::Other(e) = e {
            e.set_scene_bounds(center, radius);
        }
    }
    let accel = Accel::build(&b.shapes);
    let mut scene = Scene {
        accel,
        shapes: b.shapes,
        bsdfs: b.bsdfs,
        emitters: b.emitters,
        environment: b.environment.map(|e| e.0),
        media: b.media,
        camera: sensor.camera,
        film: sensor.film,
        sampler: sensor.sampler,
        sensor_medium,
        // Replaced below: the integrator's tables are built from the finished scene.
        integrator: Integrator::Path(IntegratorDesc::default()),
        bounds,
        emitters_unreachable: Vec::new(),
        surfaces_block_shadow_rays: false,
        only_area_emitters: false,
        constant_sphere_lights: Vec::new(),
        ray_avx2: super::world::ray_avx2_supported(),
    };
    scene.only_area_emitters =
        !scene.emitters.is_empty() && scene.emitters.iter().all(|e| matches!(e, SceneEmitter::Area { .. }));
    scene.constant_sphere_lights = integrator::volpath::constant_sphere_lights(&scene);
    scene.emitters_unreachable = integrator::enclosure::emitters_unreachable(&scene);
    scene.surfaces_block_shadow_rays = integrator::enclosure::surfaces_block_shadow_rays(&scene);
    scene.integrator = integrator::build(integrator, &scene);
    Ok(scene)
}

impl Builder<'_> {
    fn bsdf(&mut self, obj: &Rc<ObjectDesc>) -> Result<u32> {
        let key = Rc::as_ptr(obj);
        if let Some(&i) = self.bsdf_ids.get(&key) {
            return Ok(i);
        }
        let bsdf = Bsdf::from_desc(obj, self.resolver)?;
        self.bsdfs.push(bsdf);
        let i = (self.bsdfs.len() - 1) as u32;
        self.bsdf_ids.insert(key, i);
        Ok(i)
    }

    fn medium(&mut self, obj: &Rc<ObjectDesc>) -> Result<u32> {
        let key = Rc::as_ptr(obj);
        if let Some(&i) = self.medium_ids.get(&key) {
            return Ok(i);
        }
        if obj.kind != PluginKind::Medium {
            return Err(Error::at(&obj.pos, format!("expected a <medium>, found a <{}>", obj.kind.tag())));
        }
        let m = Homogeneous::from_desc(obj)?;
        self.media.push(m);
        let i = (self.media.len() - 1) as u32;
        self.medium_ids.insert(key, i);
        Ok(i)
    }

    /// Mitsuba's default BSDF for a shape without one: `diffuse` with reflectance 0.5, or 0 when
    /// the shape is an area emitter (checked against Mitsuba 3.9; media boundaries get 0.5 too).
    fn default_bsdf(&mut self, emitter: bool) -> Result<u32> {
        let slot = if emitter { self.black_bsdf } else { self.default_bsdf };
        if let Some(i) = slot {
            return Ok(i);
        }
        let pos = super::SrcPos::new("<default bsdf>", 0, 0);
        let mut props = super::desc::Props::new(PluginKind::Bsdf, "diffuse", pos.clone());
        if emitter {
            props.push("reflectance", super::desc::Value::Float(0.0), pos.clone())?;
        }
        let obj = ObjectDesc { kind: PluginKind::Bsdf, plugin: "diffuse".into(), id: None, pos, props };
        self.bsdfs.push(Bsdf::from_desc(&obj, self.resolver)?);
        let i = (self.bsdfs.len() - 1) as u32;
        if emitter {
            self.black_bsdf = Some(i);
        } else {
            self.default_bsdf = Some(i);
        }
        Ok(i)
    }

    fn emitter(&mut self, obj: &Rc<ObjectDesc>) -> Result<()> {
        if obj.plugin == "area" {
            return Err(Error::at(&obj.pos, "an area emitter must be nested inside a <shape>"));
        }
        let e = Emitter::from_desc(obj, self.resolver)?;
        let env = e.is_environment();
        self.emitters.push(SceneEmitter::Other(e));
        if env {
            if let Some((_, first)) = &self.environment {
                return Err(Error::at(
                    &obj.pos,
                    format!("a scene has at most one environment emitter (the first is at {})", first),
                ));
            }
            self.environment = Some(((self.emitters.len() - 1) as u32, obj.pos.clone()));
        }
        Ok(())
    }

    fn shape(&mut self, obj: &Rc<ObjectDesc>) -> Result<()> {
        let props = &obj.props;
        let mut geometry = Geometry::from_desc(obj, self.resolver)?;
        let index = self.shapes.len() as u32;
        let interior = match props.object_named("interior", PluginKind::Medium)? {
            Some(m) => Some(self.medium(&m)?),
            None => None,
        };
        let exterior = match props.object_named("exterior", PluginKind::Medium)? {
            Some(m) => Some(self.medium(&m)?),
            None => None,
        };
        let emitter_desc = props.object_of(PluginKind::Emitter)?;
        let bsdf = match props.object_of(PluginKind::Bsdf)? {
            Some(b) => self.bsdf(&b)?,
            None => self.default_bsdf(emitter_desc.is_some())?,
        };
        let mut emitter = None;
        if let Some(e) = emitter_desc {
            if e.plugin != "area" {
                return Err(Error::at(
                    &e.pos,
                    format!("emitter \"{}\" cannot be attached to a shape (only \"area\" can)", e.plugin),
                ));
            }
            let radiance = crate::emitter::area::from_desc(&e, self.resolver)?;
            // Light samples need the uv (the sphere's: acos, atan2) only for a textured radiance.
            match &mut geometry {
                Geometry::Sphere(s) => s.sample_uv = radiance.is_spatially_varying(),
                Geometry::Mesh(m) => m.sample_uv = radiance.is_spatially_varying(),
                Geometry::Disk(_) => {}
            }
            self.emitters.push(SceneEmitter::Area { shape: index, radiance });
            emitter = Some((self.emitters.len() - 1) as u32);
        }
        // Hits need the uv (the sphere's: acos, atan2) only when a texture of the BSDF or emitter reads it.
        let radiance_uv = matches!(emitter.map(|e| &self.emitters[e as usize]),
            Some(SceneEmitter::Area { radiance, .. }) if radiance.is_spatially_varying());
        let hit_uv = self.bsdfs[bsdf as usize].needs_uv() || radiance_uv;
        geometry.set_hit_uv(hit_uv);
        let sensor_desc = props.object_of(PluginKind::Sensor)?;
        props.finish()?;
        let shape =
            Shape { geometry, plugin: obj.plugin.clone(), id: obj.id.clone(), bsdf, emitter, interior, exterior };
        // Beyond ±1e18, products of two extents (areas, BVH costs) overflow f32 (found by fuzzing).
        let b = shape.bounds();
        let reach = b.min.abs().max(b.max.abs()).max_element();
        if !b.is_empty() && !(reach <= 1e18) {
            let msg = format!(
                "shape \"{}\" reaches {reach:e} in world space; coordinates must stay within ±1e18",
                obj.plugin
            );
            return Err(Error::at(&obj.pos, msg));
        }
        if let Some(s) = sensor_desc {
            if let Some((_, first)) = &self.meter {
                return Err(Error::at(&s.pos, format!("only one sensor is supported (the first is at {})", first)));
            }
            self.meter = Some((Sensor::irradiance_meter(&s, shape.clone())?, s.pos.clone()));
        }
        self.shapes.push(shape);
        Ok(())
    }
}
